"""Reconstruction at a continuous voxel-index position: values, gradients at voxels, jitter hash.

Positions are ``(x, y, z)`` = (i, j, k) in voxel indices, voxel centres at
integers; arrays are indexed ``[z, y, x]``. Positions outside
``[0, n-1]`` are clamped (the ray caster never asks for them, except by
rounding). :func:`prefetch_cell` asks for a cell's cache lines ahead of its reads (``_march``).
"""

from __future__ import annotations

import numpy as np

from ...jit import njit, prefetch

__all__ = ["prefetch_cell", "sample_value", "sample_table", "trilinear", "grad_at", "world_grad", "jitter01"]


@njit(cache=True, fastmath=True)
def _cell(x, n):
    """Lower corner index, upper index and fraction along one axis of length ``n`` (x clamped to [0, n - 1]).

    The indices are unsigned (``np.uintp``): indexing with them compiles to no
    negative-index wraparound, which in the samplers' inner loops cost three
    instructions and a live register per index."""
    top = n - 1
    xc = min(max(x, 0.0), np.float64(top))
    i0 = int(xc)
    return np.uintp(i0), np.uintp(min(i0 + 1, top)), xc - i0


@njit(cache=True, fastmath=True, inline="always")
def prefetch_cell(arr, x, y, z):
    """Ask for the cache lines of the voxel cell of ``arr[z, y, x]`` at index position (x, y, z), clamped to the
    array (``volumen.jit.prefetch``): the line of each of its four rows' lower voxel, which holds the upper one too
    except where a row crosses a line's end."""
    nz, ny, nx = arr.shape
    i = min(max(int(x), 0), nx - 1)
    j = min(max(int(y), 0), ny - 1)
    k = min(max(int(z), 0), nz - 1)
    j1 = min(j + 1, ny - 1)
    k1 = min(k + 1, nz - 1)
    prefetch(arr, (k, j, i))
    prefetch(arr, (k, j1, i))
    prefetch(arr, (k1, j, i))
    prefetch(arr, (k1, j1, i))


@njit(cache=True, fastmath=True, inline="always")
def sample_value(vol, x, y, z, nearest):
    """Trilinear (or nearest when ``nearest``) value of ``vol[z, y, x]`` at index position (x, y, z)."""
    nz, ny, nx = vol.shape
    if nearest:
        i = min(max(int(x + 0.5), 0), nx - 1)
        j = min(max(int(y + 0.5), 0), ny - 1)
        k = min(max(int(z + 0.5), 0), nz - 1)
        return np.float64(vol[k, j, i])
    return trilinear(vol, _cell(x, nx), _cell(y, ny), _cell(z, nz))


@njit(cache=True, fastmath=True, inline="always")
def trilinear(vol, cx, cy, cz):
    """The trilinear blend of ``vol[z, y, x]`` over one cell given per axis as ``(lower, upper, fraction)``
    (:func:`_cell`): one trilinear lookup, which the B-spline's fast form (``_bspline``) makes eight of."""
    i0, i1, fx = cx
    j0, j1, fy = cy
    k0, k1, fz = cz
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
    (the int16 samples of ``_precompute.int16_samples``)."""
    return (sample_value(vol, x, y, z, nearest) - u0) * ufac


@njit(cache=True, fastmath=True)
def grad_at(u, k, j, i, sobel):
    """Index-space gradient ``(d/di, d/dj, d/dk)`` of ``u`` at voxel ``[k, j, i]``: central differences, or the
    3x3x3 Sobel operator when ``sobel``; neighbours past the border are clamped to it."""
    nz, ny, nx = u.shape
    ip, im = min(i + 1, nx - 1), max(i - 1, 0)
    jp, jm = min(j + 1, ny - 1), max(j - 1, 0)
    kp, km = min(k + 1, nz - 1), max(k - 1, 0)
    if not sobel:
        return (0.5 * (np.float64(u[k, j, ip]) - u[k, j, im]), 0.5 * (np.float64(u[k, jp, i]) - u[k, jm, i]),
                0.5 * (np.float64(u[kp, j, i]) - u[km, j, i]))
    gi = 0.0
    gj = 0.0
    gk = 0.0
    for b in range(-1, 2):
        for a in range(-1, 2):
            wa = 2.0 if a == 0 else 1.0
            wb = 2.0 if b == 0 else 1.0
            w = wa * wb / 32.0
            # along i: neighbours (j+a, k+b)
            jj, kk = min(max(j + a, 0), ny - 1), min(max(k + b, 0), nz - 1)
            gi += w * (np.float64(u[kk, jj, ip]) - u[kk, jj, im])
            ii = min(max(i + a, 0), nx - 1)
            gj += w * (np.float64(u[kk, jp, ii]) - u[kk, jm, ii])
            jj2 = min(max(j + b, 0), ny - 1)
            gk += w * (np.float64(u[kp, jj2, ii]) - u[km, jj2, ii])
    return gi, gj, gk


@njit(cache=True, fastmath=True, inline="always")
def world_grad(u, m, k, j, i, sobel):
    """``(gx, gy, gz, |g|)``: the gradient at voxel ``[k, j, i]`` in world space (``m`` (3+, 3): index -> world
    gradients, the inverse transpose of the affine's 3x3), in sample units per mm."""
    gi, gj, gk = grad_at(u, k, j, i, sobel)
    gx = m[0, 0] * gi + m[0, 1] * gj + m[0, 2] * gk
    gy = m[1, 0] * gi + m[1, 1] * gj + m[1, 2] * gk
    gz = m[2, 0] * gi + m[2, 1] * gj + m[2, 2] * gk
    return gx, gy, gz, np.sqrt(gx * gx + gy * gy + gz * gz)


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
