"""Per-volume precomputation: int16 samples, the normals' parameters, min/max block grid.

All three are built once per volume and cached (see :mod:`._cache`); the
kernels then only read arrays.

* samples: int16 ``[z, y, x]`` for every volume (:func:`int16_samples`), so one compiled kernel per mode
  serves CT, MRI and float data alike: int16 data itself, integer data of any other type shifted (exact),
  floats and wider ranges quantized to 65,536 levels over the value range (1/16 of a table entry). With the
  pair ``(u0, ufac)``, ``(u - u0) * ufac`` is the index into the transfer-function table. NaN becomes the
  value range's low end; values past the range (``core.table_range``: an MRI's far outliers, a fill far below)
  are clamped to it.
* normals: the parameters (:func:`normal_params`: the index -> world gradient
  matrix and ``gmax``, the largest |g|); the per-voxel direction codes the kernels
  read are built from them in :mod:`._normals`. Gradients are central differences
  (or 3x3x3 Sobel) in index space, turned into world space through the inverse
  transpose of the affine, so the voxel spacing and obliquity are accounted for.
* block grid: per block of ``B^3`` voxels, the min and max of the samples in table units
  over the voxels it touches **dilated by one voxel** on every side, so a
  trilinear (or nearest) sample anywhere inside the block is bounded by them.
"""

from __future__ import annotations

import numpy as np

from ...jit import njit, run_parts
from ._sample import world_grad

__all__ = ["NLUT", "LEVELS", "int16_samples", "normal_params", "build_blocks"]

#: entries of the 1-D transfer-function table, evenly over the volume's value range
NLUT = 4096


#: int16 levels a quantized volume's value range is spread over
LEVELS = 1 << 16
_LOW = int(np.iinfo(np.int16).min)


@njit(cache=True, nogil=True)  # no fastmath: it must see NaN
def _shift_kernel(part, parts, data, vmin, scale, top, out):
    """Planes of part ``part`` of ``parts`` (``volumen.jit.run_parts``): ``rint((x - vmin) * scale)`` clamped to
    ``[0, top]``, NaN to 0, stored less 32768."""
    nz, ny, nx = data.shape
    for k in range(part * nz // parts, (part + 1) * nz // parts):
        for j in range(ny):
            for i in range(nx):
                v = np.rint((np.float64(data[k, j, i]) - vmin) * scale)
                if not (v >= 0.0):  # NaN or below
                    v = 0.0
                elif v > top:
                    v = top
                out[k, j, i] = np.int16(np.int64(v) + _LOW)


def int16_samples(data: np.ndarray, vmin: float, vmax: float, steps: int = 1,
                  in_place: bool = True) -> tuple[np.ndarray, float, float]:
    """``(u, u0, ufac)``: the samples the kernels read, with ``(u - u0) * ufac`` mapping ``[vmin, vmax]`` (data
    units; ``steps`` samples of ``data`` per unit) onto ``[0, NLUT - 1]``.

    * int16, C-contiguous and writable, ``in_place`` (``[vmin, vmax]`` holds all its values): ``data`` itself
      (no copy);
    * other integers whose range spans at most :data:`LEVELS` values: an int16 copy shifted by a whole number
      (exact);
    * floats and wider integer ranges: ``[vmin, vmax]`` quantized to :data:`LEVELS` levels (a step of
      1/16 of a table entry), out-of-range values clamped, NaN at ``vmin``.
    """
    lo, span = vmin * steps, (vmax - vmin) * steps  # the range in sample units
    per_entry = (NLUT - 1) / span  # table entries per sample unit
    if in_place and data.dtype == np.int16 and data.flags.c_contiguous and data.flags.writeable:
        return data, lo, per_entry
    exact = data.dtype.kind in "iu" and span < LEVELS
    scale = 1.0 if exact else (LEVELS - 1) / span
    top = min(LEVELS - 1.0, np.floor(span * scale + 1e-6))  # vmax (in whole units when exact): table entry 4095
    out = np.empty(data.shape, np.int16)
    run_parts(_shift_kernel, data.shape[0], data, float(lo), float(scale), float(top), out)
    return out, float(_LOW), per_entry / scale


@njit(cache=True, fastmath=True, nogil=True)
def _max_gradient(part, parts, u, m, sobel, slab_max):
    """Largest |g| (u per mm) of each z slab of part ``part`` of ``parts`` into ``slab_max`` (nz,)."""
    nz, ny, nx = u.shape
    for k in range(part * nz // parts, (part + 1) * nz // parts):
        top = 0.0
        for j in range(ny):
            for i in range(nx):
                top = max(top, np.float32(world_grad(u, m, k, j, i, sobel)[3]))
        slab_max[k] = top


def normal_params(u: np.ndarray, affine: np.ndarray, value_scale: float, sobel: bool,
                  magnitude: bool = True) -> tuple[np.ndarray, float]:
    """What the kernels need to compute normals from the samples ``u`` (one pass over the volume when
    ``magnitude``, no array of its size).

    Parameters
    ----------
    u : (nz, ny, nx) the samples (``Prepared.u``)
    affine : (4, 4) voxel (i, j, k, 1) -> world mm
    value_scale : float
        Data units per sample unit (to report magnitudes in data units / mm).
    sobel : bool
        3x3x3 Sobel instead of central differences.
    magnitude : bool
        Find the largest gradient magnitude (the pass over the volume), which only the gradient-magnitude
        codes need (gradient opacity); without it ``nrm[3, 0]`` and ``gmax`` are 0 (every code 0).

    Returns
    -------
    nrm : (4, 3) float64
        Rows 0..2: the index -> world gradient matrix (inverse transpose of the
        affine's 3x3); ``nrm[3, 0]``: 1 / gmax in sample units per mm (0 for a flat volume).
    gmax : float
        Gradient magnitude (data units / mm) of magnitude code 127.
    """
    m = np.ascontiguousarray(np.linalg.inv(np.asarray(affine, float)[:3, :3]).T)
    slab_max = np.zeros(u.shape[0] if magnitude else 0, np.float32)
    if magnitude:
        run_parts(_max_gradient, u.shape[0], u, m, bool(sobel), slab_max)
    gmax = float(slab_max.max()) if slab_max.size else 0.0
    nrm = np.zeros((4, 3), np.float64)
    nrm[:3] = m
    nrm[3, 0] = 1.0 / gmax if gmax > 0 else 0.0
    return nrm, gmax * value_scale


@njit(cache=True, nogil=True)
def _blocks_kernel(part, parts, u, b, bmin, bmax):
    """Block planes of part ``part`` of ``parts`` (contiguous) (``volumen.jit.run_parts``)."""
    nz, ny, nx = u.shape
    gz, gy, gx = bmin.shape
    for bk in range(part * gz // parts, (part + 1) * gz // parts):
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
    run_parts(_blocks_kernel, shape[0], u, int(block), bmin, bmax)
    return bmin, bmax
