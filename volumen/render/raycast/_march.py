"""The marching skeleton: one loop for every mode, specialised by the mode's pieces at compile time.

``trace_pixel(px, py, a, s, out, mode, light)`` casts the ray of one pixel:
:func:`begin_ray` finds its interval and sample grid, then the mode's
pieces (:mod:`._pieces`: ``init``, ``step``, ``finish``, and ``radius`` /
``eager`` for empty-space skipping) run in the loop below. ``mode`` and
``light`` are tags, so each (mode, shading model) pair compiles to its own
kernel with no branch on either at run time.

Sampling. The ray's drawn interval ``[t0, t1]`` (``_geometry``) is sampled
at ``t_k = t0 + (k + j) ds``, ``k = 0 .. n-1``, with ``j`` in [0, 1) the
pixel's jitter (0 without jitter) and ``n`` the number of such points in
``[t0, t1]`` (at least 1). With jitter off, the first sample is at the exact
entry and, when the length is a whole number of steps, the last at the
exact exit.

Empty-space skipping (``Settings.skip``): the walk of :mod:`._walk` goes through the skipping grid's blocks along
the ray and hands the loop the next sample in a block that can contribute (the mode's ``radius``: composite -- a
visible value in the block's range; isosurface -- the threshold in it; mip / minip -- a value past the running max
/ min; the modes that need the sample before a skipped run also get the first sample of each run), with the
parameter past which it must be asked again; the samples in between are passed over, on the same sample grid,
so skipping changes no pixel. Under adaptive sampling, a sample in a cube of coarse blocks stands
for up to ``Settings.stride`` grid steps (``_span``).

Pre-classified cells (post-classified composite, ``Settings.cells``): inside a block that must be sampled, a
sample whose voxel cell holds no visible value (``_cells``) is passed over unreconstructed; that changes no pixel
either, only the samples counted.

Prefetching: before each sample the loop asks the cache for the lines that the sample ``PREFETCH_STEPS`` grid
steps ahead will read (``_ahead``: the scan's voxel cell, and the normal codes' where the shading reads them). The
reads of a ray go where no hardware prefetcher guesses, and on a whole-abdomen CT a sample's reconstruction and
normal waited on them; a hint changes no value (docs/design.md section 6).
"""

from __future__ import annotations

import math

import numpy as np

from ...jit import claim, fetch_add, njit, run_claiming
from . import _composite, _iso, _project  # noqa: F401 - they register the mode pieces
from ._cells import cell_visible
from ._frame import FAR
from ._normals import prefetch_codes
from ._pieces import Pixel, RayEnd, Sample, finish, init, step, uses_normals
from ._ray import begin_ray, sample_at
from ._sample import prefetch_cell
from ._walk import Cursor, enter, sample_t, walk

__all__ = ["trace_pixel", "render_tiles", "PREFETCH_STEPS"]

#: grid steps ahead of a sample whose voxel cell (scan, and normal codes where the shading reads them) the loop
#: asks the cache for (:func:`_ahead`)
PREFETCH_STEPS = 4.0


@njit(cache=True, fastmath=True, inline="always")
def _span(r, s, k, t, t_check):
    """Grid steps sample ``k`` (at ``t``) stands for in a coarse block: at most ``s.stride``, every one of them
    before the far side ``t_check`` of the cube of coarse blocks ahead of it and on the ray."""
    steps = (t_check - t) / s.ds  # FAR / ds where the cube reaches the grid's end: compared before converting
    return max(min(s.stride if steps >= s.stride else int(math.ceil(steps)), r.k1 - k), 1)


@njit(cache=True, fastmath=True, inline="always")
def _ahead(r, a, s, t, light):
    """Ask for the cache lines the sample at ``t`` will read: the scan's voxel cell, and the normal codes' (and the
    gradient magnitudes' under gradient opacity) where the light tag shades with normals."""
    x, y, z = r.oi + t * r.di, r.oj + t * r.dj, r.ok + t * r.dk
    prefetch_cell(a.vol, x, y, z)
    if uses_normals(light):
        prefetch_codes(a, x, y, z)
    if s.gradient_opacity:
        prefetch_cell(a.gradient_codes, x, y, z)


@njit(cache=True, fastmath=True, inline="always")
def _clear(out, px, py):
    for c in range(4):
        out.rgba[py, px, c] = 0.0
    out.depth[py, px] = FAR
    out.value[py, px] = FAR
    out.nsamp[py, px] = 0


@njit(cache=True, fastmath=False)  # explicit: a callee inherits the caller's fastmath otherwise
def blank(out, px, py):
    """Pixel (px, py) as no ray drew it: transparent, depth inf, value NaN, no samples (not ``fastmath``: it
    writes the infinities)."""
    for c in range(4):
        out.rgba[py, px, c] = 0.0
    out.depth[py, px] = np.inf
    out.value[py, px] = np.nan
    out.nsamp[py, px] = 0


@njit(cache=True, fastmath=False)  # explicit: a callee inherits the caller's fastmath otherwise
def _blank_tile(out, x0, y0, x1, y1):
    """:func:`blank` every pixel of columns x0 .. x1 - 1, rows y0 .. y1 - 1: one simple loop per array (stores the
    compiler vectorizes)."""
    for py in range(y0, y1):
        for px in range(x0, x1):
            for c in range(4):
                out.rgba[py, px, c] = 0.0
        for px in range(x0, x1):
            out.depth[py, px] = np.inf
        for px in range(x0, x1):
            out.value[py, px] = np.nan
        for px in range(x0, x1):
            out.nsamp[py, px] = 0


@njit(cache=True, fastmath=False)  # explicit: a callee inherits the caller's fastmath otherwise
def _settle(out, px, py):
    """A depth / value the mode left at FAR (nothing hit) becomes inf / NaN (not ``fastmath``, as :func:`blank`;
    it compares only the finite values the pieces wrote)."""
    if out.depth[py, px] >= 0.5 * FAR:
        out.depth[py, px] = np.inf
    if out.value[py, px] >= 0.5 * FAR:
        out.value[py, px] = np.nan


@njit(cache=True, fastmath=True, inline="always")
def trace_pixel(px, py, a, s, out, mode, light):
    """Cast the ray of pixel (px, py); write ``out.rgba / depth / value / nsamp`` there (depth inf and value NaN
    where there is none)."""
    r = begin_ray(px, py, a, s)
    if not r.t1 >= r.t0:
        blank(out, px, py)
        return
    _clear(out, px, py)
    st, taken, done, have = init(mode, light, r, a, s)
    coarse = False
    t_check = r.t0 - 1.0
    k = r.k0
    tc = sample_t(r, s, k) - s.ds  # a step before the first sample: the walk starts in its block
    bk, bj, bi = enter(r, a, s, tc + s.ds)
    cur = Cursor(bk, bj, bi, tc, False)
    while k < r.k1 and not done:
        t = sample_t(r, s, k)
        if s.skip and t >= t_check:
            kk, t_check, coarse, cur = walk(mode, r, a, s, st, k, cur)
            if kk != k:
                have = False
                k = kk
                if k >= r.k1:
                    break
                t = sample_t(r, s, k)
        span = _span(r, s, k, t, t_check) if coarse else 1
        _ahead(r, a, s, t + PREFETCH_STEPS * s.ds, light)
        if s.cells and not cell_visible(a, r.oi + t * r.di, r.oj + t * r.dj, r.ok + t * r.dk):
            have = False  # a transparent cell: the sample (and the steps it stands for) would add nothing
            k += span
            continue
        st, extra, done = step(mode, light, r, a, s, st, Sample(k, t, sample_at(r, a, s, t), have, span))
        taken += 1 + extra
        have = span == 1
        k += span
    finish(mode, light, r, a, s, st, RayEnd(taken, have), Pixel(out, px, py))
    _settle(out, px, py)


@njit(cache=True, fastmath=True, nogil=True, _nrt=False)
def _trace_tiles(counter, order, tile, a, s, out, mode, light):
    """The rows ``order[claim(counter)]`` (``_cpu.frame_tiles``; ``volumen.jit.run_claiming``) until none is left:
    ``(tile, 0)`` traced, every pixel's ``trace_pixel`` inlined, its samples and hit rays added to
    ``counter[1]`` / ``counter[2]``; ``(tile, run)`` a run of blank tiles. Compiled without reference counting
    (nothing in it allocates): reading an array from the records then costs no atomic increments, which threads
    sharing the arrays would contend for, and the records are passed once per thread, not once per pixel."""
    h, w = out.depth.shape
    ntx = (w + tile - 1) // tile
    n = claim(counter)
    while n < order.shape[0]:
        c, run = order[n, 0], order[n, 1]
        x0, y0 = (c % ntx) * tile, (c // ntx) * tile
        if run > 0:
            _blank_tile(out, x0, y0, min(x0 + run * tile, w), min(y0 + tile, h))
            n = claim(counter)
            continue
        samples = hits = 0
        for py in range(y0, min(y0 + tile, h)):
            for px in range(x0, min(x0 + tile, w)):
                trace_pixel(px, py, a, s, out, mode, light)
                samples += out.nsamp[py, px]
                hits += out.nsamp[py, px] > 0
        fetch_add(counter, 1, samples)
        fetch_add(counter, 2, hits)
        n = claim(counter)


def render_tiles(order, tile, a, s, out, mode, light) -> tuple[int, int]:
    """Every row of ``order`` (``_cpu.frame_tiles``: traced tiles, then runs of blank ones) on every thread;
    ``(samples, hit rays)``."""
    samples, hits = run_claiming(_trace_tiles, order.shape[0], order, tile, a, s, out, mode, light, counts=2)
    return int(samples), int(hits)
