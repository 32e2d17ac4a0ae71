"""Normals as the kernels read them: one 16-bit direction code per voxel, decoded through a table, kept only in
the bricks of the volume a shown sample can read.

Per voxel the world-space gradient (central differences, or 3x3x3 Sobel, in
index space, turned into world space through the inverse transpose of the
affine: ``_sample.world_grad``) is stored as its unit direction, quantized
with the octahedral map onto a 255 x 255 grid (largest angular error 0.93
degree, mean 0.3) -- code ``1 + 255 qu + qv``, code 0 for a vanishing gradient.
:data:`DIRS` decodes a code to its unit vector (the zero vector for code 0), packed in one uint32.

The codes are kept per brick (:func:`brick_codes`): bricks start every :data:`BRICK` voxels along each axis and
hold :data:`SPAN` = BRICK + 1, so the cells whose lower corner lies in a brick have all eight corners in it (one
brick per sample). ``normal_codes`` is a pool of bricks stacked along its first axis (slot ``s`` is
``normal_codes[s * SPAN:(s + 1) * SPAN]``), ``normal_slots`` the slot of each brick of the volume, 0 for a brick
whose codes are not kept (slot 0 holds zeros: the zero vector). A frame keeps the bricks its transfer function can show
(``_tables.block_visibility`` of the blocks of BRICK voxels, whose ranges cover their cells' corners), so a CT
shown as bone keeps the codes of the bone's bricks only; every brick where what is shown is not known from the
table alone (isosurfaces, labels, pre-integration). Two bytes a kept voxel, built in one parallel pass over the
kept bricks: computing the gradients of the 8 corners at every sample cost the ray caster most of its shading
time. A sample is shaded only where its opacity is above zero, which only a kept brick's cells give, so the
pictures are those of codes for every voxel, to the bit.

Where gradient-magnitude opacity is on, a second byte per voxel holds the
magnitude code ``round(127 sqrt(|g| / gmax))`` (built only then, for every voxel).

:func:`sample_normal` interpolates the decoded directions of the 8 voxels
around a position trilinearly (the nearest voxel's when ``nearest``), and their
magnitude codes alike: the result is not unit; the shading normalizes it.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from ...jit import njit, prefetch, run_parts
from ._sample import _cell, world_grad

__all__ = ["DIRS", "DIR_HALF", "NO_CODES", "NO_SLOTS", "BRICK", "BrickCodes", "encode_normals", "brick_codes",
           "brick_grid", "covers", "SPAN", "prefetch_codes", "sample_normal", "unpack"]

#: levels per axis of the octahedral grid
Q = 255


#: a packed direction's components are ``q / DIR_HALF - 1``, ``q`` in ``0 .. 2 DIR_HALF`` (10 bits; 0 exactly at
#: ``q = DIR_HALF``, so code 0 decodes to the zero vector)
DIR_HALF = 511
#: bits of a packed component, and where x and y start (z in the lowest bits)
_BITS = 10
_MASK = (1 << _BITS) - 1
_SX, _SY = 2 * _BITS, _BITS


def _decode_table() -> np.ndarray:
    """code -> unit direction, float64 (1 + Q^2, 3); row 0 the zero vector."""
    c = np.arange(1, Q * Q + 1)
    u = (c - 1) // Q / (Q - 1) * 2.0 - 1.0
    v = (c - 1) % Q / (Q - 1) * 2.0 - 1.0
    z = 1.0 - np.abs(u) - np.abs(v)
    neg = z < 0.0
    x = np.where(neg, (1.0 - np.abs(v)) * np.sign(u), u)
    y = np.where(neg, (1.0 - np.abs(u)) * np.sign(v), v)
    d = np.stack([x, y, z], axis=1)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    return np.vstack([np.zeros((1, 3)), d])


def _packed(dirs: np.ndarray) -> np.ndarray:
    """Directions (n, 3) as three 10-bit components in one uint32 each: x in bits 20-29, y in 10-19, z in 0-9."""
    q = np.rint((dirs + 1.0) * DIR_HALF).astype(np.uint32)
    return (q[:, 0] << _SX) | (q[:, 1] << _SY) | q[:, 2]


def unpack(p: np.ndarray) -> np.ndarray:
    """The directions (n, 3) float64 of packed codes ``p`` (:data:`DIRS` rows)."""
    p = np.asarray(p, np.uint32)
    q = np.stack([(p >> _SX) & _MASK, (p >> _SY) & _MASK, p & _MASK], axis=-1)
    return q / DIR_HALF - 1.0


#: code -> unit direction (world), packed: one uint32 per code (1 + Q^2,), three 10-bit components (:func:`unpack`;
#: largest error 1e-3 per component, 0.06 degree, against the codes' own 0.93). A third of a float32 table's
#: 780 KiB, and one load per voxel: the ray caster reads it at random, and on 366x303x336 CTs headlight frames
#: took 0.84-0.95x the time of the float table's (paired in one process)
DIRS = _packed(_decode_table())
#: the placeholders of a frame that reads no codes (pool, slots): one object each, so a device keeps them between
#: frames
NO_CODES = np.zeros((1, 1, 1), np.uint16)
NO_SLOTS = np.zeros((1, 1, 1), np.int32)
#: bricks of codes start every BRICK voxels (a power of two; its log2) along each axis and hold SPAN: the upper
#: corners of the cells whose lower corner lies in the brick too, so a cell reads one brick
BRICK = 8
_SHIFT = 3
SPAN = BRICK + 1
#: a volume's kept codes are built again, for the bricks a frame shows, where they hold more than this many times
#: as many bricks
SLACK = 2


@njit(cache=True, fastmath=True, inline="always")
def _encode(gx, gy, gz, g):
    """The code of the world gradient (gx, gy, gz) of length g."""
    if g <= 1e-6:
        return 0
    s = 1.0 / (abs(gx) + abs(gy) + abs(gz))
    u, v = gx * s, gy * s
    if gz < 0.0:
        u, v = (1.0 - abs(v)) * (1.0 if u >= 0.0 else -1.0), (1.0 - abs(u)) * (1.0 if v >= 0.0 else -1.0)
    qu = min(max(int((u + 1.0) * (0.5 * (Q - 1)) + 0.5), 0), Q - 1)
    qv = min(max(int((v + 1.0) * (0.5 * (Q - 1)) + 0.5), 0), Q - 1)
    if gz == 0.0:  # in the plane z = 0 (a slab constant along z): kept on the equator |u| + |v| = 1, so the
        h = (Q - 1) // 2  # decoded direction has no z either (it missed the plane by up to 0.93 degree)
        rest = h - abs(qu - h)
        qv = h + rest if v >= 0.0 else h - rest
    return 1 + qu * Q + qv


@njit(cache=True, fastmath=True, nogil=True)
def _direction_kernel(part, parts, u, m, sobel, dirs):
    """Direction codes of the planes of part ``part`` of ``parts`` (contiguous) (``volumen.jit.run_parts``)."""
    nz, ny, nx = u.shape
    for k in range(part * nz // parts, (part + 1) * nz // parts):
        for j in range(ny):
            for i in range(nx):
                gx, gy, gz, g = world_grad(u, m, k, j, i, sobel)
                dirs[k, j, i] = _encode(gx, gy, gz, g)


@njit(cache=True, fastmath=True, nogil=True)
def _magnitude_kernel(part, parts, u, m, sobel, inv_gmax, mags):
    """Magnitude codes of the planes of part ``part`` of ``parts`` (contiguous) (``volumen.jit.run_parts``)."""
    nz, ny, nx = u.shape
    for k in range(part * nz // parts, (part + 1) * nz // parts):
        for j in range(ny):
            for i in range(nx):
                _, _, _, g = world_grad(u, m, k, j, i, sobel)
                mags[k, j, i] = np.uint8(np.rint(127.0 * np.sqrt(min(g * inv_gmax, 1.0))))


@njit(cache=True, fastmath=True, nogil=True)
def _brick_kernel(part, parts, u, m, sobel, bricks, pool):
    """Direction codes of the bricks of part ``part`` of ``parts`` (``volumen.jit.run_parts``): brick ``bricks[b]``
    (its (k, j, i) in bricks), :data:`SPAN` voxels along each axis from its first, into slot ``b + 1`` of ``pool``;
    its voxels past the volume's end take the codes of the last voxel (never read: the samplers clamp to it)."""
    nz, ny, nx = u.shape
    n = bricks.shape[0]
    for b in range(part * n // parts, (part + 1) * n // parts):
        base = (b + 1) * SPAN
        for dk in range(SPAN):
            k = min(bricks[b, 0] * BRICK + dk, nz - 1)
            for dj in range(SPAN):
                j = min(bricks[b, 1] * BRICK + dj, ny - 1)
                for di in range(SPAN):
                    i = min(bricks[b, 2] * BRICK + di, nx - 1)
                    gx, gy, gz, g = world_grad(u, m, k, j, i, sobel)
                    pool[base + dk, dj, di] = _encode(gx, gy, gz, g)


def encode_normals(u: np.ndarray, nrm: np.ndarray, sobel: bool, *, directions=True, magnitudes=False):
    """``(direction codes uint16, magnitude codes uint8)`` of every voxel of the samples ``u`` [z, y, x]; each a
    (1, 1, 1) placeholder where not asked for. ``nrm``: ``_precompute.normal_params``' (4, 3) (gradient matrix,
    1 / gmax). The frames read the direction codes by brick (:func:`brick_codes`)."""
    m = np.ascontiguousarray(nrm[:3])
    dirs = np.empty(u.shape, np.uint16) if directions else NO_CODES
    mags = np.empty(u.shape, np.uint8) if magnitudes else np.zeros((1, 1, 1), np.uint8)
    if directions:
        run_parts(_direction_kernel, u.shape[0], u, m, bool(sobel), dirs)
    if magnitudes:
        run_parts(_magnitude_kernel, u.shape[0], u, m, bool(sobel), float(nrm[3, 0]), mags)
    return dirs, mags


def brick_grid(shape) -> tuple[int, int, int]:
    """Bricks of :data:`BRICK` voxels along each axis of a volume of ``shape`` [z, y, x]."""
    return tuple(-(-int(n) // BRICK) for n in shape)


class BrickCodes(NamedTuple):
    """The direction codes of some bricks of a volume (:func:`brick_codes`)."""

    #: (slots * SPAN, SPAN, SPAN) uint16: slot 0 zeros, then the kept bricks (``Arrays.normal_codes``)
    pool: np.ndarray
    slots: np.ndarray  #: (gz, gy, gx) int32: each brick's slot, 0 where not kept (``Arrays.normal_slots``)
    kept: np.ndarray   #: (gz, gy, gx) bool: the bricks kept


def brick_codes(u: np.ndarray, nrm: np.ndarray, sobel: bool, keep: np.ndarray | None = None) -> BrickCodes:
    """The direction codes of the bricks ``keep`` (bool, :func:`brick_grid` of ``u``'s shape; None: every brick)
    of the samples ``u`` [z, y, x]; ``nrm`` as in :func:`encode_normals`."""
    grid = brick_grid(u.shape)
    kept = np.ones(grid, bool) if keep is None else np.asarray(keep, bool)
    which = np.flatnonzero(kept)
    slots = np.zeros(grid, np.int32)
    slots.ravel()[which] = np.arange(1, which.size + 1, dtype=np.int32)
    pool = np.empty(((which.size + 1) * SPAN, SPAN, SPAN), np.uint16)
    pool[:SPAN] = 0
    bricks = np.ascontiguousarray(np.stack(np.unravel_index(which, grid), axis=1).astype(np.int64))
    if which.size:
        run_parts(_brick_kernel, which.size, u, np.ascontiguousarray(nrm[:3]), bool(sobel), bricks, pool)
    return BrickCodes(pool, slots, kept)


def covers(codes: BrickCodes | None, keep: np.ndarray | None) -> bool:
    """Whether ``codes`` hold every brick of ``keep`` (None: every brick) and not more than :data:`SLACK` times
    as many (a frame showing less frees the rest when its codes are built again)."""
    if codes is None:
        return False
    if keep is None:
        return bool(codes.kept.all())
    need = int(np.count_nonzero(keep))
    return (not np.any(keep & ~codes.kept)) and int(np.count_nonzero(codes.kept)) <= SLACK * need + 64


class Cell(NamedTuple):
    """A voxel cell's codes in the pool (:func:`_cell_at`)."""

    z0: Any  #: its lower corner in ``normal_codes``: its brick's first plane plus the corner's place in the brick
    y0: Any
    x0: Any
    dz: Any  #: the steps to its upper corners (0 where clamped at the volume's end)
    dy: Any
    dx: Any


@njit(cache=True, fastmath=True, inline="always")
def _cell_at(a, x, y, z):
    """The codes of the voxel cell at index position (x, y, z) (clamped to the volume, as ``_sample._cell`` clamps
    it): its :class:`Cell` and the fractions ``(fx, fy, fz)``."""
    nz, ny, nx = a.vol.shape
    i0, i1, fx = _cell(x, nx)
    j0, j1, fy = _cell(y, ny)
    k0, k1, fz = _cell(z, nz)
    sh, low = np.uintp(_SHIFT), np.uintp(BRICK - 1)
    base = np.uintp(a.normal_slots[k0 >> sh, j0 >> sh, i0 >> sh]) * np.uintp(SPAN)
    return Cell(base + (k0 & low), j0 & low, i0 & low, k1 - k0, j1 - j0, i1 - i0), (fx, fy, fz)


@njit(cache=True, fastmath=True, inline="always")
def prefetch_codes(a, x, y, z):
    """Ask for the cache lines of the codes of the voxel cell at index position (x, y, z) (``volumen.jit.prefetch``):
    the line of each of its four rows' lower voxel, in its brick."""
    c, _ = _cell_at(a, x, y, z)
    prefetch(a.normal_codes, (c.z0, c.y0, c.x0))
    prefetch(a.normal_codes, (c.z0, c.y0 + c.dy, c.x0))
    prefetch(a.normal_codes, (c.z0 + c.dz, c.y0, c.x0))
    prefetch(a.normal_codes, (c.z0 + c.dz, c.y0 + c.dy, c.x0))


@njit(cache=True, fastmath=True, inline="always")
def _component(p):
    """The three 10-bit components ``q`` of packed direction ``p``, as floats (``q / DIR_HALF - 1`` each)."""
    return np.float64((p >> _SX) & _MASK), np.float64((p >> _SY) & _MASK), np.float64(p & _MASK)


@njit(cache=True, fastmath=True, inline="always")
def _direction(qx, qy, qz):
    """The direction of components ``q`` (or of a weighted sum of components whose weights sum to 1)."""
    return qx * (1.0 / DIR_HALF) - 1.0, qy * (1.0 / DIR_HALF) - 1.0, qz * (1.0 / DIR_HALF) - 1.0


@njit(cache=True, fastmath=True, inline="always")
def _weight(fx, fy, fz, n):
    """The trilinear weight of corner ``n`` of a cell (bits: the upper voxel along z, y, x)."""
    return (fz if n & 4 else 1.0 - fz) * (fy if n & 2 else 1.0 - fy) * (fx if n & 1 else 1.0 - fx)


@njit(cache=True, fastmath=True, inline="always")
def _code(a, c, n):
    """The code of corner ``n`` of the cell ``c`` (:func:`_cell_at`; bits of ``n``: the upper voxel along z, y, x)."""
    none = np.uintp(0)
    return a.normal_codes[c.z0 + (c.dz if n & 4 else none), c.y0 + (c.dy if n & 2 else none),
                   c.x0 + (c.dx if n & 1 else none)]


@njit(cache=True, fastmath=True, inline="always")
def _corner(a, c, f, n):
    """Corner ``n`` of the cell ``c`` (:func:`_cell_at`, fractions ``f``): its direction's components ``q`` times its
    trilinear weight."""
    fx, fy, fz = f
    w = _weight(fx, fy, fz, n)
    qx, qy, qz = _component(a.normal_dirs[_code(a, c, n)])
    return w * qx, w * qy, w * qz


@njit(cache=True, fastmath=True, inline="always")
def _add(p, q):
    return p[0] + q[0], p[1] + q[1], p[2] + q[2]


@njit(cache=True, fastmath=True, inline="always")
def sample_normal(a, x, y, z, nearest, want_dir, want_mag):
    """``(gx, gy, gz, code)`` at index position (x, y, z): the interpolated directions of the codes
    (``a.normal_codes`` by brick through ``a.normal_slots``, decoded by ``a.normal_dirs``) when ``want_dir`` and
    magnitude codes of ``a.gradient_codes`` when ``want_mag`` (0 otherwise)."""
    nz, ny, nx = a.vol.shape
    gx = gy = gz = gm = 0.0
    if nearest:
        i = min(max(int(x + 0.5), 0), nx - 1)
        j = min(max(int(y + 0.5), 0), ny - 1)
        k = min(max(int(z + 0.5), 0), nz - 1)
        if want_dir:  # the nearest voxel: a corner of the cell the position lies in
            c, f = _cell_at(a, x, y, z)
            fx, fy, fz = f
            n = (4 if fz >= 0.5 else 0) + (2 if fy >= 0.5 else 0) + (1 if fx >= 0.5 else 0)
            qx, qy, qz = _component(a.normal_dirs[_code(a, c, n)])
            gx, gy, gz = _direction(qx, qy, qz)
        if want_mag:
            gm = np.float64(a.gradient_codes[k, j, i])
        return gx, gy, gz, gm
    i0, i1, fx = _cell(x, nx)
    j0, j1, fy = _cell(y, ny)
    k0, k1, fz = _cell(z, nz)
    if want_dir:  # summed as a tree of the 8 weighted corners (a shorter chain of dependent adds than in turn)
        c, f = _cell_at(a, x, y, z)
        gx, gy, gz = _add(_add(_add(_corner(a, c, f, 0), _corner(a, c, f, 1)),
                               _add(_corner(a, c, f, 2), _corner(a, c, f, 3))),
                          _add(_add(_corner(a, c, f, 4), _corner(a, c, f, 5)),
                               _add(_corner(a, c, f, 6), _corner(a, c, f, 7))))
        gx, gy, gz = _direction(gx, gy, gz)  # the trilinear weights sum to 1: the offset is taken off once
    if want_mag:
        for n in range(8):
            gm += _weight(fx, fy, fz, n) * a.gradient_codes[k1 if n & 4 else k0, j1 if n & 2 else j0,
                                                            i1 if n & 1 else i0]
    return gx, gy, gz, gm

