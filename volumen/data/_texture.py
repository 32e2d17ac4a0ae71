"""Smooth random fields for the phantoms: heterogeneous enhancement, parenchyma texture.

Contrast in a real vessel is not one value: the bolus mixes unevenly with blood,
and streaming leaves brighter and darker regions a centimetre or so across; lung
parenchyma varies with gravity and perfusion over a few centimetres. A phantom
gets that as a smooth Gaussian random field (white noise filtered by a Gaussian
of ``sigma`` mm), zero mean and unit standard deviation, which its builder scales
to a relative amplitude. It is made on a coarse grid (four samples per ``sigma``)
and interpolated, so a field costs a few milliseconds however fine the phantom's grid.
"""

from __future__ import annotations

import numpy as np

from ._canvas import VoxelGrid

__all__ = ["smooth_field"]


def smooth_field(grid: VoxelGrid, sigma: float, seed: int) -> np.ndarray:
    """A zero-mean, unit-variance Gaussian random field on ``grid`` (float32 ``[z, y, x]``), correlated over
    ``sigma`` mm (the Gaussian filter's standard deviation); deterministic for a ``seed``."""
    from scipy import ndimage

    if not sigma > 0:
        raise ValueError(f"sigma must be > 0 mm, got {sigma!r}")
    coarse_h = sigma / 4.0  # mm between coarse samples: the field varies little over a quarter of sigma
    extent = np.array(grid.shape) * np.array(grid.spacing)
    coarse = np.maximum(np.ceil(extent / coarse_h).astype(int) + 1, 2)
    rng = np.random.default_rng(seed)
    white = rng.standard_normal(tuple(coarse))
    field = ndimage.gaussian_filter(white, 4.0, mode="wrap")
    field = (field - field.mean()) / field.std()
    # voxel centres in coarse-sample units
    coords = [np.arange(n) * h / coarse_h for n, h in zip(grid.shape, grid.spacing, strict=True)]
    zz, yy, xx = np.meshgrid(*coords, indexing="ij", sparse=True)
    out = ndimage.map_coordinates(field, np.broadcast_arrays(zz, yy, xx), order=1, mode="nearest")
    return ((out - out.mean()) / out.std()).astype(np.float32)
