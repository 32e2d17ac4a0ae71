"""Normals as the kernels read them: one 16-bit direction code per voxel, decoded through a table.

Per voxel the world-space gradient (central differences, or 3x3x3 Sobel, in
index space, turned into world space through the inverse transpose of the
affine: ``_sample.world_grad``) is stored as its unit direction, quantized
with the octahedral map onto a 255 x 255 grid (largest angular error 0.93
degree, mean 0.3) -- code ``1 + 255 qu + qv``, code 0 for a vanishing gradient.
That is 2 bytes a voxel (an int16 volume's own size), built once per volume
in one parallel pass, where computing the gradients of the 8 corners at every
sample cost the ray caster most of its shading time. :data:`DIRS` decodes a
code to its unit vector (the zero vector for code 0), packed in one uint32.

Where gradient-magnitude opacity is on, a second byte per voxel holds the
magnitude code ``round(127 sqrt(|g| / gmax))`` (built only then).

:func:`sample_normal` interpolates the decoded directions of the 8 voxels
around a position trilinearly (the nearest voxel's when ``nearest``), and their
magnitude codes alike: the result is not unit; the shading normalizes it.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ...jit import run_parts
from ._sample import _cell, world_grad

__all__ = ["DIRS", "DIR_HALF", "NO_CODES", "encode_normals", "sample_normal", "unpack"]

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
#: took 0.84-0.95x the time of the float table's (issue 27, paired in one process)
DIRS = _packed(_decode_table())
#: the placeholder of a frame that reads no codes: one object, so a device keeps it between frames
NO_CODES = np.zeros((1, 1, 1), np.uint16)


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
def _encode_kernel(part, parts, u, m, sobel, inv_gmax, dirs, mags, want_dir, want_mag):
    """Planes of part ``part`` of ``parts`` (contiguous) (``volumen.jit.run_parts``); ``dirs`` / ``mags`` written
    where ``want_dir`` / ``want_mag`` (said, not guessed from the arrays' shapes: a single-slice volume's planes
    are as many as a placeholder's)."""
    nz, ny, nx = u.shape
    for k in range(part * nz // parts, (part + 1) * nz // parts):
        for j in range(ny):
            for i in range(nx):
                gx, gy, gz, g = world_grad(u, m, k, j, i, sobel)
                if want_dir:
                    dirs[k, j, i] = _encode(gx, gy, gz, g)
                if want_mag:
                    mags[k, j, i] = np.uint8(np.rint(127.0 * np.sqrt(min(g * inv_gmax, 1.0))))


def encode_normals(u: np.ndarray, nrm: np.ndarray, sobel: bool, *, directions=True, magnitudes=False):
    """``(direction codes uint16, magnitude codes uint8)`` of the samples ``u`` [z, y, x]; each a (1, 1, 1)
    placeholder where not asked for. ``nrm``: ``_precompute.normal_params``' (4, 3) (gradient matrix, 1 / gmax)."""
    dirs = np.empty(u.shape, np.uint16) if directions else NO_CODES
    mags = np.empty(u.shape, np.uint8) if magnitudes else np.zeros((1, 1, 1), np.uint8)
    if directions or magnitudes:
        run_parts(_encode_kernel, u.shape[0], u, np.ascontiguousarray(nrm[:3]), bool(sobel), float(nrm[3, 0]),
                    dirs, mags, bool(directions), bool(magnitudes))
    return dirs, mags


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
def _corner(a, k, j, i, fx, fy, fz, n):
    """Corner ``n`` of a cell, voxel ``[k, j, i]``: its direction's components ``q`` times its trilinear weight."""
    w = _weight(fx, fy, fz, n)
    qx, qy, qz = _component(a.normal_dirs[a.normal_codes[k, j, i]])
    return w * qx, w * qy, w * qz


@njit(cache=True, fastmath=True, inline="always")
def _add(p, q):
    return p[0] + q[0], p[1] + q[1], p[2] + q[2]


@njit(cache=True, fastmath=True, inline="always")
def sample_normal(a, x, y, z, nearest, want_dir, want_mag):
    """``(gx, gy, gz, code)`` at index position (x, y, z): the interpolated directions of ``a.normal_codes``
    (decoded by ``a.normal_dirs``) when ``want_dir`` and magnitude codes of ``a.gradient_codes`` when ``want_mag``
    (0 otherwise)."""
    nz, ny, nx = a.vol.shape
    gx = gy = gz = gm = 0.0
    if nearest:
        i = min(max(int(x + 0.5), 0), nx - 1)
        j = min(max(int(y + 0.5), 0), ny - 1)
        k = min(max(int(z + 0.5), 0), nz - 1)
        if want_dir:
            qx, qy, qz = _component(a.normal_dirs[a.normal_codes[k, j, i]])
            gx, gy, gz = _direction(qx, qy, qz)
        if want_mag:
            gm = np.float64(a.gradient_codes[k, j, i])
        return gx, gy, gz, gm
    i0, i1, fx = _cell(x, nx)
    j0, j1, fy = _cell(y, ny)
    k0, k1, fz = _cell(z, nz)
    if want_dir:  # summed as a tree of the 8 weighted corners (a shorter chain of dependent adds than in turn)
        gx, gy, gz = _add(_add(_add(_corner(a, k0, j0, i0, fx, fy, fz, 0), _corner(a, k0, j0, i1, fx, fy, fz, 1)),
                               _add(_corner(a, k0, j1, i0, fx, fy, fz, 2), _corner(a, k0, j1, i1, fx, fy, fz, 3))),
                          _add(_add(_corner(a, k1, j0, i0, fx, fy, fz, 4), _corner(a, k1, j0, i1, fx, fy, fz, 5)),
                               _add(_corner(a, k1, j1, i0, fx, fy, fz, 6), _corner(a, k1, j1, i1, fx, fy, fz, 7))))
        gx, gy, gz = _direction(gx, gy, gz)  # the trilinear weights sum to 1: the offset is taken off once
    if want_mag:
        for n in range(8):
            gm += _weight(fx, fy, fz, n) * a.gradient_codes[k1 if n & 4 else k0, j1 if n & 2 else j0,
                                                            i1 if n & 1 else i0]
    return gx, gy, gz, gm

