"""A grown lumen redrawn at its sections' own half-way values: the 3D wall the inscribed spheres are measured in.

A lumen grown over one range of values (:func:`volumen.endoscopy.lumen_wall`) stops short where the
contrast is dimmer than at its start (a bolus washing out along the vessel, contrast layered across it).
The sections of :mod:`._sections` find their own threshold there; :func:`locally_thresholded` carries
those thresholds back into the volume: each voxel within :data:`BAND` voxels of the grown lumen takes the
threshold of the nearest centerline point's section, and the lumen is the voxels beyond it joined to the
grown lumen, holes filled.
"""

from __future__ import annotations

import numpy as np

__all__ = ["locally_thresholded", "BAND"]

#: how far (voxels) past the grown lumen the redrawn lumen may reach
BAND = 4


def locally_thresholded(volume, lumen: np.ndarray, points: np.ndarray, thresholds: np.ndarray,
                        sign: float) -> np.ndarray:
    """bool ``lumen.shape``: ``lumen`` redrawn at the nearest of ``points``' (N, 3 world mm) ``thresholds``
    (data units; NaN: keep the grown lumen there); ``sign`` +1 for a lumen brighter than its wall."""
    from scipy import ndimage
    from scipy.spatial import cKDTree

    ok = np.isfinite(thresholds)
    zyx = np.argwhere(lumen)
    if not ok.any() or zyx.size == 0:
        return np.asarray(lumen, bool)
    lo = np.maximum(zyx.min(axis=0) - BAND - 1, 0)
    hi = np.minimum(zyx.max(axis=0) + BAND + 2, lumen.shape)
    box = tuple(slice(a, b) for a, b in zip(lo, hi, strict=True))
    grown = np.asarray(lumen[box], bool)
    band = ndimage.binary_dilation(grown, iterations=BAND)
    idx = np.argwhere(band)
    world = volume.index_to_world((idx + lo)[:, ::-1].astype(float))
    _, nearest = cKDTree(points[ok]).query(world)
    values = np.asarray(volume.data[box], np.float32)[tuple(idx.T)]
    beyond = np.zeros_like(band)
    beyond[tuple(idx.T)] = sign * (values - thresholds[ok][nearest]) > 0
    labels, _ = ndimage.label(beyond | grown & ~band)
    keep = np.unique(labels[grown & beyond])
    redrawn = ndimage.binary_fill_holes(np.isin(labels, keep[keep > 0]))
    out = np.zeros(lumen.shape, bool)
    out[box] = redrawn
    return out
