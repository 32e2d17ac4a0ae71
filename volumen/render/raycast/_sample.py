"""Reconstruction at a continuous voxel-index position: values, normals, jitter hash.

Positions are ``(x, y, z)`` = (i, j, k) in voxel indices, voxel centres at
integers; arrays are indexed ``[z, y, x]``. Positions outside
``[0, n-1]`` are clamped (the ray caster never asks for them, except by
rounding).
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["sample_value", "sample_table", "sample_normal", "jitter01"]


@njit(cache=True, fastmath=True)
def _cell(x, n):
    """Lower corner index, upper index and fraction along one axis of length ``n``."""
    if x <= 0.0:
        return 0, 0, 0.0
    top = n - 1
    if x >= top:
        return top, top, 0.0
    i0 = int(x)
    return i0, i0 + 1, x - i0


@njit(cache=True, fastmath=True, inline="always")
def sample_value(vol, x, y, z, nearest):
    """Trilinear (or nearest when ``nearest``) value of ``vol[z, y, x]`` at index position (x, y, z)."""
    nz, ny, nx = vol.shape
    if nearest:
        i = min(max(int(x + 0.5), 0), nx - 1)
        j = min(max(int(y + 0.5), 0), ny - 1)
        k = min(max(int(z + 0.5), 0), nz - 1)
        return np.float64(vol[k, j, i])
    i0, i1, fx = _cell(x, nx)
    j0, j1, fy = _cell(y, ny)
    k0, k1, fz = _cell(z, nz)
    c00 = vol[k0, j0, i0] + fx * (vol[k0, j0, i1] - vol[k0, j0, i0])
    c01 = vol[k0, j1, i0] + fx * (vol[k0, j1, i1] - vol[k0, j1, i0])
    c10 = vol[k1, j0, i0] + fx * (vol[k1, j0, i1] - vol[k1, j0, i0])
    c11 = vol[k1, j1, i0] + fx * (vol[k1, j1, i1] - vol[k1, j1, i0])
    c0 = c00 + fy * (c01 - c00)
    c1 = c10 + fy * (c11 - c10)
    return np.float64(c0 + fz * (c1 - c0))


@njit(cache=True, fastmath=True, inline="always")
def sample_table(vol, u0, ufac, x, y, z, nearest):
    """The value at (x, y, z) in transfer-function table units: ``(v - u0) * ufac`` of the stored samples
    (the raw data, or an already normalized copy with ``u0 = 0, ufac = 1``)."""
    return (sample_value(vol, x, y, z, nearest) - u0) * ufac


@njit(cache=True, fastmath=True, inline="always")
def sample_normal(nrm, x, y, z, nearest):
    """Interpolated packed normal at (x, y, z).

    Returns ``(gx, gy, gz, code)``: the world-space gradient direction (not
    unit; zero where the data is flat) and the gradient-magnitude code
    (0..127), see ``_precompute``.
    """
    nz, ny, nx = nrm.shape[0], nrm.shape[1], nrm.shape[2]
    if nearest:
        i = min(max(int(x + 0.5), 0), nx - 1)
        j = min(max(int(y + 0.5), 0), ny - 1)
        k = min(max(int(z + 0.5), 0), nz - 1)
        return (np.float64(nrm[k, j, i, 0]), np.float64(nrm[k, j, i, 1]), np.float64(nrm[k, j, i, 2]),
                np.float64(nrm[k, j, i, 3]))
    i0, i1, fx = _cell(x, nx)
    j0, j1, fy = _cell(y, ny)
    k0, k1, fz = _cell(z, nz)
    gx = 0.0
    gy = 0.0
    gz = 0.0
    gm = 0.0
    for c in range(2):  # z
        k = k1 if c else k0
        wz = fz if c else 1.0 - fz
        for b in range(2):  # y
            j = j1 if b else j0
            wzy = wz * (fy if b else 1.0 - fy)
            w0 = wzy * (1.0 - fx)
            w1 = wzy * fx
            gx += w0 * nrm[k, j, i0, 0] + w1 * nrm[k, j, i1, 0]
            gy += w0 * nrm[k, j, i0, 1] + w1 * nrm[k, j, i1, 1]
            gz += w0 * nrm[k, j, i0, 2] + w1 * nrm[k, j, i1, 2]
            gm += w0 * nrm[k, j, i0, 3] + w1 * nrm[k, j, i1, 3]
    return gx, gy, gz, gm


@njit(cache=True)
def jitter01(x, y, seed):
    """Deterministic hash of pixel ``(x, y)`` and frame ``seed`` to [0, 1) (integer avalanche hash)."""
    m = 0xFFFFFFFF
    h = (x * 73856093) ^ (y * 19349663) ^ ((seed + 1) * 83492791)
    h &= m
    h = ((h ^ 61) ^ (h >> 16)) & m
    h = (h + (h << 3)) & m
    h ^= h >> 4
    h = (h * 0x27D4EB2D) & m
    h ^= h >> 15
    return (h & 0xFFFFFF) / 16777216.0
