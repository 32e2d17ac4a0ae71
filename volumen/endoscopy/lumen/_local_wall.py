"""A grown lumen redrawn at local half-way values, and the smooth wall a flight draws from it.

A lumen grown over one range of values (:func:`~volumen.endoscopy.find_lumen`) stops short where the contrast is
dimmer than at its start (a bolus washing out along the vessel, contrast layered across it, a jet of unopacified
blood): the wall threshold runs through the blood itself and the drawn wall folds. Along a centerline:

* :func:`local_thresholds` -- at each centerline point the half-way value between the lumen's dimmest blood
  there (the :data:`DIM` percentile of the grown lumen's voxels a voxel or more inside it, nearest that point)
  and its wall's value (the median of the voxels :data:`RING` voxels outside it, nearest that point, not read
  below the lumen estimate's wall value: a ring past a thin wall reads the lung or fat beyond it): the
  half maximum of the vessel's edge where its blood is dimmest, so no layer of blood is cut off;
* :func:`locally_thresholded` -- the lumen redrawn: each voxel within :data:`BAND` voxels of the grown lumen
  takes the threshold of the nearest centerline point, and the lumen is the voxels beyond it joined to the
  grown lumen, holes filled;
* :func:`smooth_wall` -- for a lumen brighter than its wall whose redrawn interior holds more than
  :data:`UNEVEN` of voxels on the wall's side of the global threshold (the values inside vary more than the
  threshold allows), the :class:`~volumen.endoscopy.LumenWall` drawn as the redrawn lumen's smoothed boundary
  (smoothed by :data:`SMOOTH` voxels, then drawn as a segmentation's, ``shape_only``); otherwise the wall as it
  was. A lumen darker than its wall (air) keeps its wall: round a thin airway wall the values a few voxels out
  are the lung's, not the wall's.
"""

from __future__ import annotations

import numpy as np

from ._drawn_wall import LumenWall

__all__ = ["local_thresholds", "locally_thresholded", "smooth_wall", "uneven_share"]

#: how far (voxels) past the grown lumen the redrawn lumen may reach
BAND = 4
#: the wall's values are read this far (voxels, from, to) outside the grown lumen
RING = (1.5, 3.0)
#: the lumen's value near a point is this percentile of its voxels there: its dimmest blood (a layer, a jet of
#: unopacified blood) is lumen too, and the wall is drawn half-way between it and the wall's value
DIM = 10.0
#: the redrawn lumen is smoothed by a Gaussian of this many voxels of the smallest spacing (noise roughens its edge
#: voxel by voxel) ...
SMOOTH = 2.5
#: ... at most this share of the lumen's median radius (a Gaussian shrinks a tube by about sigma^2 / 2 r)
SMOOTH_SHARE = 0.3
#: the share of the redrawn lumen's interior on the wall's side of the global threshold that makes it uneven ...
UNEVEN = 0.01
#: ... its interior: this many voxels or more inside it (past the partial-volume edge its wall is drawn at)
INTERIOR = 2.0


def _box(lumen: np.ndarray) -> tuple[slice, ...]:
    zyx = np.argwhere(lumen)
    lo = np.maximum(zyx.min(axis=0) - BAND - 1, 0)
    hi = np.minimum(zyx.max(axis=0) + BAND + 2, lumen.shape)
    return tuple(slice(a, b) for a, b in zip(lo, hi, strict=True))


def _nearest(volume, box, idx: np.ndarray, points: np.ndarray) -> np.ndarray:
    """The index of the nearest of ``points`` (world mm) to each voxel ``idx`` (rows of z, y, x in ``box``)."""
    from scipy.spatial import cKDTree

    lo = np.array([s.start for s in box])
    world = volume.index_to_world((idx + lo)[:, ::-1].astype(float))
    return cKDTree(points).query(world)[1]


def _percentiles(values: np.ndarray, label: np.ndarray, n: int, pct: float) -> np.ndarray:
    """The ``pct`` percentile (nearest rank) of ``values`` per label ``0..n-1``; NaN where fewer than four
    voxels carry it."""
    counts = np.bincount(label, minlength=n)
    ordered = values[np.lexsort((values, label))]
    first = np.concatenate([[0], np.cumsum(counts)[:-1]])
    rank = first + np.floor(pct / 100.0 * np.maximum(counts - 1, 0)).astype(int)
    out = np.full(n, np.nan)
    ok = counts >= 4
    out[ok] = ordered[rank[ok]]
    return out


def local_thresholds(volume, lumen: np.ndarray, points: np.ndarray, wall: float | None = None) -> np.ndarray:
    """(N,) data units: the half-way value between the grown ``lumen``'s (bool ``[z, y, x]``, brighter than its
    wall) value and its wall's nearest each of ``points`` (N, 3 world mm); NaN where either is not measurable.
    ``wall`` (data units): the lowest the wall's value is read as (a ring past a thin wall reads the lung or the
    fat beyond it, not the wall)."""
    from scipy import ndimage

    box = _box(lumen)
    grown = np.asarray(lumen[box], bool)
    data = np.asarray(volume.data[box], np.float32)
    depth = ndimage.distance_transform_edt(grown)
    away = ndimage.distance_transform_edt(~grown)
    halves = []
    for sel, pct in ((depth >= 1.0, DIM), ((away >= RING[0]) & (away <= RING[1]), 50.0)):
        idx = np.argwhere(sel)
        halves.append(_percentiles(data[tuple(idx.T)], _nearest(volume, box, idx, points), len(points), pct))
    if wall is not None:
        halves[1] = np.maximum(halves[1], wall)
    return 0.5 * (halves[0] + halves[1])


def locally_thresholded(volume, lumen: np.ndarray, points: np.ndarray, thresholds: np.ndarray,
                        sign: float) -> np.ndarray:
    """bool ``lumen.shape``: ``lumen`` redrawn at the nearest of ``points``' (N, 3 world mm) ``thresholds``
    (data units; NaN: keep the grown lumen there); ``sign`` +1 for a lumen brighter than its wall."""
    from scipy import ndimage

    ok = np.isfinite(thresholds)
    if not ok.any() or not lumen.any():
        return np.asarray(lumen, bool)
    box = _box(lumen)
    grown = np.asarray(lumen[box], bool)
    band = ndimage.binary_dilation(grown, iterations=BAND)
    idx = np.argwhere(band)
    values = np.asarray(volume.data[box], np.float32)[tuple(idx.T)]
    beyond = np.zeros_like(band)
    beyond[tuple(idx.T)] = sign * (values - thresholds[ok][_nearest(volume, box, idx, points[ok])]) > 0
    labels, _ = ndimage.label(beyond | grown & ~band)
    keep = np.unique(labels[grown & beyond])
    redrawn = ndimage.binary_fill_holes(np.isin(labels, keep[keep > 0]))
    out = np.zeros(lumen.shape, bool)
    out[box] = redrawn
    return out


def uneven_share(volume, lumen: np.ndarray, threshold: float, sign: float) -> float:
    """The share of ``lumen``'s interior (:data:`INTERIOR` voxels or more inside) on the wall's side of ``threshold``
    (``sign`` +1 for a lumen brighter than its wall)."""
    from scipy import ndimage

    box = _box(lumen)
    inner = ndimage.distance_transform_edt(lumen[box]) >= INTERIOR
    values = np.asarray(volume.data[box], np.float32)[inner]
    return float(np.mean(sign * (values - threshold) <= 0)) if values.size else 0.0


def _smoothed(lumen: np.ndarray, sigma) -> np.ndarray:
    """``lumen`` smoothed by a Gaussian of ``sigma`` voxels (per axis) and cut at one half, its largest
    component."""
    from scipy import ndimage

    box = _box(lumen)
    out = np.zeros(lumen.shape, bool)
    calm = ndimage.gaussian_filter(lumen[box].astype(np.float32), sigma) > 0.5
    labels, n = ndimage.label(calm)
    if n:
        out[box] = labels == 1 + int(np.argmax(np.bincount(labels.ravel())[1:]))
    return out


def _radius(volume, lumen: np.ndarray, points: np.ndarray) -> float:
    """The median distance (voxels of the smallest spacing) from ``points`` (world mm) to ``lumen``'s boundary."""
    from scipy import ndimage

    box = _box(lumen)
    h = np.asarray(volume.spacing, float)
    depth = ndimage.distance_transform_edt(lumen[box], sampling=h / h.min())
    lo = np.array([b.start for b in box])
    zyx = np.rint(volume.world_to_index(points)[:, ::-1]).astype(int) - lo
    zyx = np.clip(zyx, 0, np.array(depth.shape) - 1)
    return float(np.median(depth[tuple(zyx.T)]))


def smooth_wall(volume, wall: LumenWall, centerline) -> LumenWall:
    """``wall`` (grown from the data) drawn as its lumen's smoothed boundary where the values inside it vary more
    than its threshold allows: redrawn at local half-way values along ``centerline``, smoothed by a Gaussian of
    :data:`SMOOTH` voxels (at most :data:`SMOOTH_SHARE` of its median radius along the centerline); else
    ``wall``."""
    est = wall.estimate
    sign = -est.sign  # +1: the lumen brighter than its wall
    if sign < 0 or wall.shape_only:
        return wall
    points = np.asarray(centerline.points, float)
    thresholds = local_thresholds(volume, wall.mask, points, est.wall)
    redrawn = locally_thresholded(volume, wall.mask, points, thresholds, sign)
    if uneven_share(volume, redrawn, est.threshold, sign) <= UNEVEN:
        return wall
    h = np.asarray(volume.spacing, float)
    sigma = min(SMOOTH, SMOOTH_SHARE * _radius(volume, redrawn, points)) * h.min() / h  # the same mm on every axis
    smooth = _smoothed(redrawn, tuple(sigma))
    return LumenWall(smooth if smooth.any() else redrawn, est, shape_only=True)
