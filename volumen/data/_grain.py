"""What makes a painted whole-region scan read like a scan: tissue texture and the scanner's correlated noise.

* :func:`texture_field`: a Gaussian random field of unit standard deviation whose features are about
  ``scale`` mm across (white noise on a coarse lattice, smoothed and interpolated trilinearly onto the
  grid): the slow variation of an organ's attenuation, the strands of fat.
* :func:`scanner_noise`: white Gaussian noise smoothed by the reconstruction kernel (a Gaussian of
  ``corr`` mm), scaled to ``std`` HU: the grain of a CT image, independent of the voxel size (a finer
  grid resolves the same grain, as an upsampled scan does).

Both are seeded: the same arguments give the same bytes. Unlike :func:`._texture.smooth_field` (a Gaussian
field on a lattice of a quarter of its sigma, interpolated with ``map_coordinates``), the texture's lattice is
half its feature size and is interpolated separably, so millimetre-scale texture over a 400 mm body stays cheap.
"""

from __future__ import annotations

import numpy as np

from ._canvas import VoxelGrid

__all__ = ["texture_field", "scanner_noise"]


def texture_field(grid: VoxelGrid, scale: float, seed: int) -> np.ndarray:
    """float32 ``grid.shape`` field, mean ~0 and standard deviation ~1, varying over ``scale`` mm."""
    from scipy import ndimage

    step = scale / 2.0  # lattice spacing: features of ~2 lattice cells
    ext = np.array(grid.shape) * np.array(grid.spacing)  # (z, y, x) mm
    coarse_shape = tuple(int(np.ceil(e / step)) + 4 for e in ext)
    rng = np.random.default_rng(seed)
    coarse = ndimage.gaussian_filter(rng.standard_normal(coarse_shape), 1.0, mode="wrap")
    coarse /= coarse.std()
    coords = [np.arange(n) * h / step + 1.5 for n, h in zip(grid.shape, grid.spacing, strict=True)]
    zz = coords[0][:, None, None]
    yy = coords[1][None, :, None]
    xx = coords[2][None, None, :]
    return _trilinear(coarse.astype(np.float32), zz, yy, xx)


def _trilinear(c: np.ndarray, zz, yy, xx) -> np.ndarray:
    """``c`` interpolated at the separable positions ``zz`` (nz, 1, 1), ``yy`` (1, ny, 1), ``xx`` (1, 1, nx)."""
    out = None
    for axis, pos in enumerate((zz, yy, xx)):
        i0 = np.floor(pos).astype(np.int64)
        f = (pos - i0).astype(np.float32)
        a = np.take(c if out is None else out, i0.ravel(), axis=axis)
        b = np.take(c if out is None else out, i0.ravel() + 1, axis=axis)
        shape = [1, 1, 1]
        shape[axis] = -1
        f = f.reshape(shape)
        out = a + f * (b - a)
    return np.ascontiguousarray(out, dtype=np.float32)


def scanner_noise(grid: VoxelGrid, std: float, corr: float, seed: int) -> np.ndarray:
    """float32 ``grid.shape`` noise of ``std`` HU, correlated over ``corr`` mm (Gaussian kernel sigma)."""
    from scipy import ndimage

    rng = np.random.default_rng(seed)
    white = rng.standard_normal(grid.shape, dtype=np.float32)
    sigma = [corr / h for h in grid.spacing]
    out = ndimage.gaussian_filter(white, sigma, mode="nearest", truncate=3.0)
    out *= np.float32(std / max(float(out.std()), 1e-12))
    return out
