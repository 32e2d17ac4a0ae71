"""Per-volume precomputation: normalized samples, gradient normals, min/max block grid.

All three are built once per volume and cached (see :mod:`._cache`); the
kernels then only read arrays.

* ``normalized``: float32 ``[z, y, x]``, the data mapped linearly so that the
  volume's value range ``[vmin, vmax]`` becomes ``[0, NLUT - 1]``: a sample is
  directly an index into the transfer-function table. NaN becomes 0.
* ``normals``: int16 ``[z, y, x, 4]``: the world-space unit gradient times 32767
  in channels 0..2 (zero where the gradient vanishes), and in channel 3 the
  magnitude code ``127 * sqrt(|g| / gmax)`` (|g| in data units per mm).
  Gradients are central differences (or 3x3x3 Sobel) in index space, turned
  into world space through the inverse transpose of the affine, so the voxel
  spacing and obliquity are accounted for.
* block grid: per block of ``B^3`` voxels, the min and max of ``normalized``
  over the voxels it touches **dilated by one voxel** on every side, so a
  trilinear (or nearest) sample anywhere inside the block is bounded by them.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

__all__ = ["NLUT", "normalize", "build_normals", "build_blocks"]

#: entries of the 1-D transfer-function table, evenly over the volume's value range
NLUT = 4096


@njit(parallel=True, cache=True)  # no fastmath: it must see NaN
def _normalize_kernel(data, vmin, scale, out):
    nz, ny, nx = data.shape
    top = np.float32(NLUT - 1)
    for k in prange(nz):
        for j in range(ny):
            for i in range(nx):
                v = (np.float64(data[k, j, i]) - vmin) * scale
                if not (v >= 0.0):  # NaN or below
                    v = 0.0
                elif v > top:
                    v = top
                out[k, j, i] = v


def normalize(data: np.ndarray, vmin: float, vmax: float) -> np.ndarray:
    """float32 copy of ``data`` with ``[vmin, vmax]`` mapped onto ``[0, NLUT - 1]``."""
    out = np.empty(data.shape, np.float32)
    scale = (NLUT - 1) / (vmax - vmin) if vmax > vmin else 0.0
    _normalize_kernel(data, float(vmin), float(scale), out)
    return out


@njit(cache=True, fastmath=True)
def _grad_at(u, k, j, i, sobel):
    nz, ny, nx = u.shape
    ip, im = min(i + 1, nx - 1), max(i - 1, 0)
    jp, jm = min(j + 1, ny - 1), max(j - 1, 0)
    kp, km = min(k + 1, nz - 1), max(k - 1, 0)
    if not sobel:
        return (0.5 * (u[k, j, ip] - u[k, j, im]), 0.5 * (u[k, jp, i] - u[k, jm, i]),
                0.5 * (u[kp, j, i] - u[km, j, i]))
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
            gi += w * (u[kk, jj, ip] - u[kk, jj, im])
            ii = min(max(i + a, 0), nx - 1)
            gj += w * (u[kk, jp, ii] - u[kk, jm, ii])
            jj2 = min(max(j + b, 0), ny - 1)
            gk += w * (u[kp, jj2, ii] - u[km, jj2, ii])
    return gi, gj, gk


@njit(cache=True, fastmath=True, inline="always")
def _world_grad(u, m, k, j, i, sobel):
    gi, gj, gk = _grad_at(u, k, j, i, sobel)
    gx = m[0, 0] * gi + m[0, 1] * gj + m[0, 2] * gk
    gy = m[1, 0] * gi + m[1, 1] * gj + m[1, 2] * gk
    gz = m[2, 0] * gi + m[2, 1] * gj + m[2, 2] * gk
    return gx, gy, gz, np.sqrt(gx * gx + gy * gy + gz * gz)


@njit(parallel=True, cache=True, fastmath=True)
def _max_gradient(u, m, sobel, slab_max):
    """Largest |g| (u per mm) of each z slab into ``slab_max`` (nz,)."""
    nz, ny, nx = u.shape
    for k in prange(nz):
        top = 0.0
        for j in range(ny):
            for i in range(nx):
                top = max(top, np.float32(_world_grad(u, m, k, j, i, sobel)[3]))
        slab_max[k] = top


@njit(parallel=True, cache=True, fastmath=True)
def _normals_kernel(u, m, sobel, inv_gmax, out):
    """Unit world gradient x 32767 into out[..., :3], magnitude code ``127 sqrt(|g| / gmax)`` into out[..., 3]."""
    nz, ny, nx = u.shape
    for k in prange(nz):
        for j in range(ny):
            for i in range(nx):
                gx, gy, gz, g = _world_grad(u, m, k, j, i, sobel)
                g = np.float32(g)  # the magnitude as the float32 array of the first version held it
                if g > 1e-6:
                    s = 32767.0 / g
                    out[k, j, i, 0] = np.int16(np.rint(gx * s))
                    out[k, j, i, 1] = np.int16(np.rint(gy * s))
                    out[k, j, i, 2] = np.int16(np.rint(gz * s))
                else:
                    out[k, j, i, 0] = 0
                    out[k, j, i, 1] = 0
                    out[k, j, i, 2] = 0
                out[k, j, i, 3] = np.int16(np.rint(127.0 * np.sqrt(min(g * inv_gmax, 1.0))))


def build_normals(u: np.ndarray, affine: np.ndarray, value_scale: float, sobel: bool) -> tuple[np.ndarray, float]:
    """Packed normals of the normalized volume ``u`` (two passes, no temporary volume).

    Parameters
    ----------
    u : (nz, ny, nx) float32, normalized samples
    affine : (4, 4) voxel (i, j, k, 1) -> world mm
    value_scale : float
        Data units per normalized unit (to report magnitudes in data units / mm).
    sobel : bool
        3x3x3 Sobel instead of central differences.

    Returns
    -------
    normals : (nz, ny, nx, 4) int16
        Unit gradient direction x 32767 (8-bit directions band visibly in specular
        highlights) and the magnitude code 0..127.
    gmax : float
        Gradient magnitude (data units / mm) of magnitude code 127.
    """
    m = np.ascontiguousarray(np.linalg.inv(np.asarray(affine, float)[:3, :3]).T)
    slab_max = np.zeros(u.shape[0], np.float32)
    _max_gradient(u, m, bool(sobel), slab_max)
    gmax = float(slab_max.max()) if slab_max.size else 0.0
    out = np.empty(u.shape + (4,), np.int16)
    _normals_kernel(u, m, bool(sobel), 1.0 / gmax if gmax > 0 else 0.0, out)
    return out, gmax * value_scale


@njit(parallel=True, cache=True)
def _blocks_kernel(u, b, bmin, bmax):
    nz, ny, nx = u.shape
    gz, gy, gx = bmin.shape
    for bk in prange(gz):
        k0, k1 = max(bk * b - 1, 0), min((bk + 1) * b + 1, nz - 1)
        for bj in range(gy):
            j0, j1 = max(bj * b - 1, 0), min((bj + 1) * b + 1, ny - 1)
            for bi in range(gx):
                i0, i1 = max(bi * b - 1, 0), min((bi + 1) * b + 1, nx - 1)
                lo = np.inf
                hi = -np.inf
                for k in range(k0, k1 + 1):
                    for j in range(j0, j1 + 1):
                        for i in range(i0, i1 + 1):
                            v = u[k, j, i]
                            lo = min(lo, v)
                            hi = max(hi, v)
                bmin[bk, bj, bi] = lo
                bmax[bk, bj, bi] = hi


def build_blocks(u: np.ndarray, block: int) -> tuple[np.ndarray, np.ndarray]:
    """Min and max of ``u`` per block of ``block^3`` voxels, dilated by one voxel.

    Block ``(bk, bj, bi)`` covers continuous index positions
    ``[bi*B, (bi+1)*B) x ...``; its bounds cover voxels ``bi*B - 1 .. (bi+1)*B + 1``.
    Returns two float32 arrays of shape ``ceil(shape / B)`` (``[z, y, x]``).
    """
    shape = tuple(-(-n // block) for n in u.shape)
    bmin = np.empty(shape, np.float32)
    bmax = np.empty(shape, np.float32)
    _blocks_kernel(u, int(block), bmin, bmax)
    return bmin, bmax
