"""Marching cubes, pass 1 and the row bookkeeping the later passes share (kernel in ``_mc_kernel.py``).

Inside flags are one byte per sample (``value > level``) in grid rows padded with zeros
to whole 64-bit words, read eight at a time as ``uint64``; rows all outside or all inside
share one stored row each. Pass 1 reads the volume in its own dtype (no converted copy)
and keeps per row, as flying edges does, the *trim* ``trim[r] = (lo, hi, ends, flag row)``:
the word range ``[lo, hi)`` holding the row's crossed x edges (``lo = nw, hi = 0`` when
there are none), its end flags (bit 0: first sample inside, bit 1: last sample inside)
and the row of flags to read. Two rows can differ only inside the union of their trims, unless their end
flags differ, which widens the range to that end. Later passes visit only those words,
so rows far from the surface cost a few comparisons.

Work is split into contiguous runs of rows cut where the estimated cost (busy words,
crossed edges, triangles) is balanced -- bone levels put the surface in a few slices --
four runs per thread, handed out one at a time to the calling thread and the other threads
of the one thread driver (``volumen.jit.run_parts``; the kernels release the GIL; a calling
thread that only waited for the others cost a thread switch per run, up to a fifth of a
mesh's time on two cores).
A thread that the system holds back delays only the run it holds; the others take the
rest (Numba's parallel loops give each thread a fixed share and wait for the slowest,
which on a busy machine cost up to twice the time).
"""

from __future__ import annotations

import numba
import numpy as np

from ..jit import njit, run_parts

U0 = np.uint64(0)
U1 = np.uint64(1)
U8 = np.uint64(8)
U56 = np.uint64(56)
ONES = np.uint64(0x0101010101010101)  # byte sums by multiplication
BYTE_INDEX = np.uint64(0x0001020304050607)  # (1 << 8k) * BYTE_INDEX >> 56 == k


@njit(inline="always")
def low_byte(d):
    """Index of the lowest non-zero byte of a word whose bytes are 0 or 1 (d != 0)."""
    return np.int64(((d & (~d + U1)) * BYTE_INDEX) >> U56)


@njit(inline="always")
def count_bytes(d):
    """Number of bytes set in a word whose bytes are 0 or 1."""
    return np.int64((d * ONES) >> U56)


@njit(inline="always")
def valid(w, n):
    """Word mask of the bytes 8 w + k < n."""
    lim = n - 8 * w
    if lim >= 8:
        return ~U0
    if lim <= 0:
        return U0
    return (U1 << np.uint64(8 * lim)) - U1


@njit(inline="always")
def next_shift(words, r, w, nw):
    """The row's word w shifted down one byte, with the next word's first byte on top: flags at x + 1."""
    nxt = words[r, w + 1] if w + 1 < nw else U0
    return (words[r, w] >> U8) | (nxt << U56)


@njit(inline="always")
def x_cross(words, r, w, nw, nx):
    """Crossed x edges (x, x + 1) of row r in word w."""
    return (words[r, w] ^ next_shift(words, r, w, nw)) & valid(w, nx - 1)


@njit(inline="always")
def words2(trim, a, b, nw):
    """Word range ``[lo, hi)`` outside which rows a and b hold equal flags and no crossed x edge."""
    lo = min(trim[a, 0], trim[b, 0])
    hi = max(trim[a, 1], trim[b, 1])
    e = trim[a, 2] ^ trim[b, 2]
    return (0 if e & 1 else lo), (nw if e & 2 else hi)


@njit(inline="always")
def words4(trim, a, b, c, d, nw):
    """:func:`words2` for the four rows of a cube row."""
    lo = min(min(trim[a, 0], trim[b, 0]), min(trim[c, 0], trim[d, 0]))
    hi = max(max(trim[a, 1], trim[b, 1]), max(trim[c, 1], trim[d, 1]))
    e = (trim[a, 2] ^ trim[b, 2]) | (trim[a, 2] ^ trim[c, 2]) | (trim[a, 2] ^ trim[d, 2])
    return (0 if e & 1 else lo), (nw if e & 2 else hi)


@njit(inline="always")
def _row_crossings(words, r, nw, nx):
    """Crossed x edges of row r and the word range ``[lo, hi)`` holding them (``(nw, 0)`` when none)."""
    n = 0
    lo = nw
    hi = 0
    for w in range(nw):
        c = count_bytes(x_cross(words, r, w, nw, nx))
        if c:
            n += c
            lo = min(lo, w)
            hi = w + 1
    return n, lo, hi


@njit(cache=True, _nrt=False, nogil=True)
def sign_rows(s, r0, r1, o):
    """Pass 1 on grid rows [r0, r1) of :class:`~._mc_records.Sign` ``s`` into :class:`~._mc_records.SignOut`
    ``o``: flags ``sgn = vol > level`` (zero padding) of the rows that have both inside and outside samples,
    and per row the crossed x edges, the trim, the flag row to read (``trim[r, 3]``), the inside samples and,
    where ``bits`` is ``vol`` viewed as uint32 (float32 data; else an empty array), the NaN and infinite
    values, found from their exponent bits.

    ``sgn`` has two rows more than the grid, filled by the caller: all outside (row ``nz * ny``) and all
    inside (the last); a row all outside or all inside (most rows, at a bone level) writes no flags and
    reads that shared row instead, and skips the search for crossings.

    ``vol`` is read in its own dtype and compared with ``level`` in that dtype (see
    :func:`threshold`: the flags a float32 copy would give). The sample loops are plain
    sweeps the compiler vectorises. Like the kernels of the other passes it runs without
    Numba's reference counting.
    """
    vol, level, sgn, words, bits = s
    nxc, trim, ninside, nbad = o
    nz, ny, nx = vol.shape
    nw = words.shape[1]
    check = bits.size > 0
    for r in range(r0, r1):
        z = r // ny
        y = r - z * ny
        src = vol[z, y]
        inside = 0
        for x in range(nx):
            inside += src[x] > level
        bad = 0
        if check:
            b = bits[z, y]
            for x in range(nx):
                bad += (b[x] & 0x7F800000) == 0x7F800000
        nbad[r] = bad
        ninside[r] = inside
        if inside == 0 or inside == nx:
            nxc[r], trim[r, 0], trim[r, 1] = 0, nw, 0
            trim[r, 2] = 0 if inside == 0 else 3
            trim[r, 3] = nz * ny + (inside == nx)
            continue
        row = sgn[r]
        for x in range(nx):
            row[x] = src[x] > level
        for x in range(nx, row.shape[0]):
            row[x] = 0
        nxc[r], trim[r, 0], trim[r, 1] = _row_crossings(words, r, nw, nx)
        trim[r, 2] = np.int64(row[0]) | (np.int64(row[nx - 1]) << 1)
        trim[r, 3] = r


def threshold(dtype: np.dtype, level: float):
    """``level`` as :func:`sign_rows` compares it with samples of ``dtype``, so that ``v > t`` is
    ``float32(v) > float32(level)``: the float32 level for float32 data; for integers (exact in float32)
    the largest integer not above it. None when that falls outside the dtype's range."""
    lvl = np.float32(level)
    if dtype.kind == "f":
        return lvl
    t, info = np.floor(lvl), np.iinfo(dtype)
    return dtype.type(t) if info.min <= t <= info.max else None


#: estimated cost (2.5-5 ns each on one core: pass 2 of the aorta at a vessel level, 0.39 M, took 2 ms alone) below
#: which a pass runs on the calling thread
SERIAL_COST = 100_000
#: runs per thread: enough for a late thread's share to be taken by the others, few enough to cost nothing
RUNS_PER_THREAD = 4


@njit(cache=True)
def running_sums(a, start):
    """``out[i] = start + a[0] + ... + a[i - 1]`` for i = 0 .. len(a) (int64; the last is the total): a
    compiled loop, three times faster than ``np.cumsum`` on the per-row counts."""
    out = np.empty(a.shape[0] + 1, np.int64)
    acc = np.int64(start)
    for i in range(a.shape[0]):
        out[i] = acc
        acc += a[i]
    out[a.shape[0]] = acc
    return out


@njit(cache=True)
def count_costs(trim, nxc):
    """Per grid row ``(span, cost of pass 2)``: the words in its trim, and ``4 + 2 span + nxc``."""
    n = nxc.shape[0]
    span = np.empty(n, np.int64)
    cost = np.empty(n, np.int64)
    for r in range(n):
        s = max(trim[r, 1] - trim[r, 0], 0)
        span[r] = s
        cost[r] = 4 + 2 * s + nxc[r]
    return span, cost


@njit(cache=True)
def emit_costs(span, nxc, nyc, nzc, ntri, nz, ny):
    """Per grid row ``(vertices, cost of pass 3)``: its crossed edges, and ``4 + span + 4 vertices`` plus twice
    the triangles of its cube row."""
    n = nxc.shape[0]
    per_row = np.empty(n, np.int64)
    cost = np.empty(n, np.int64)
    for r in range(n):
        z = r // ny
        y = r - z * ny
        v = nxc[r] + nyc[r] + nzc[r]
        per_row[r] = v
        cost[r] = 4 + span[r] + 4 * v + (2 * ntri[z * (ny - 1) + y] if z < nz - 1 and y < ny - 1 else 0)
    return per_row, cost


def balanced_runs(cost: np.ndarray, parts: int) -> np.ndarray:
    """Bounds ``b`` (``parts + 1``, int64) cutting ``range(len(cost))`` into contiguous runs of about equal
    total cost; run p is ``range(b[p], b[p + 1])``."""
    total = running_sums(np.asarray(cost, np.int64), 0)[1:]
    cuts = np.searchsorted(total, total[-1] * np.arange(1, parts) // parts, side="right")
    return np.concatenate([[0], cuts, [len(cost)]]).astype(np.int64)


def run_pass(rows_fn, cost: np.ndarray, head: tuple, tail: tuple, scratch: int = 0) -> None:
    """Run ``rows_fn(*head, r0, r1, *tail)`` over all rows: on this thread when the work is small, else over
    runs of balanced cost handed out one at a time to ``numba.get_num_threads()`` threads, this one included
    (the one thread driver, ``volumen.jit.run_parts``: each thread's part takes runs until none is left). With
    ``scratch``, ``rows_fn`` gets one more argument: an int64 scratch row of that length, its own for each run."""
    threads = numba.get_num_threads()
    parts = 1 if threads == 1 or cost.sum() < SERIAL_COST else threads * RUNS_PER_THREAD
    extra = [np.empty((parts, scratch), np.int64)] if scratch else []
    if parts == 1:
        rows_fn(*head, 0, len(cost), *tail, *(e[0] for e in extra))
        return
    runs = balanced_runs(cost, parts)
    todo = iter(range(parts))  # shared: each next() under the GIL hands a run to exactly one thread

    def work(_part, _parts):
        for p in todo:
            rows_fn(*head, runs[p], runs[p + 1], *tail, *(e[p] for e in extra))

    run_parts(work, threads)
