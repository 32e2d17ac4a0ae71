"""Contrast-tagged fluid in an air lumen: a prepared colon holds air above a level of bright fluid, one lumen.

For CT colonography the residual fluid is tagged with an oral contrast agent, so it
is brighter than the wall (a few hundred HU and more) and pools on the dependent
side under a horizontal surface. The air lumen grown from a point in the air stops
at that surface, since the fluid is on the wall's side of the threshold.
:func:`add_tagged_fluid` finds it and joins it to the lumen:

1. the values in a shell two voxels thick outside the air lumen, on the wall's side
   of the threshold, split in two (Otsu); a bright class standing apart from the wall
   (by :data:`~volumen.endoscopy._polarity.SEPARATION` pooled standard deviations, its
   median at least as far above the wall's value as the wall is above the threshold,
   so an enhancing wall is not taken for it) is a candidate fluid of value ``F``;
2. where the air touches values past ``(wall + F) / 2``, the touching air voxels must
   lie on a plane (root-mean-square distance at most one voxel, by a least-squares
   fit) within 15 degrees of a horizontal plane of the scan (normal along one of its
   axes: the table is flat; 15 degrees leaves room for a meniscus and a voxel's
   staircase): a fluid level. Other bright contacts (bone, a vessel) are not flat;
3. the fluid is grown over values past ``(wall + F) / 2`` from the voxels under the
   level, never more than a voxel above it;
4. the partial-volume layer between air and fluid (voxels next to both) joins them.
"""

from __future__ import annotations

import numpy as np

__all__ = ["add_tagged_fluid"]

#: the largest tilt of a fluid level from a plane of the scan's axes, degrees (see the module docstring)
LEVEL_TILT = 15.0
#: the fewest air voxels a fluid level touches: a patch three voxels across
LEVEL_VOXELS = 9


def _bright_class(values: np.ndarray, wall: float, threshold: float) -> float | None:
    from skimage.filters import threshold_otsu

    from ._point_estimate import SEPARATION

    if values.size < LEVEL_VOXELS or np.ptp(values) <= 0:
        return None
    t = float(threshold_otsu(values))
    low, high = values[values <= t], values[values > t]
    if high.size < LEVEL_VOXELS or low.size == 0:
        return None
    pooled = np.sqrt(0.5 * (low.var() + high.var()))
    f = float(np.median(high))
    if f - float(np.median(low)) < SEPARATION * pooled or f - wall < wall - threshold:
        return None
    return f


def _level(volume, points: np.ndarray) -> np.ndarray | None:
    """The unit normal of the plane through voxel ``points`` (k, zyx) when they are a flat, horizontal level."""
    if len(points) < LEVEL_VOXELS:
        return None
    world = volume.index_to_world(points[:, ::-1].astype(float))
    centre = world.mean(axis=0)
    _, s, vt = np.linalg.svd(world - centre, full_matrices=False)
    normal = vt[-1]
    if s[-1] / np.sqrt(len(world)) > float(max(volume.spacing)):
        return None
    if np.degrees(np.arccos(min(np.max(np.abs(normal)), 1.0))) > LEVEL_TILT:
        return None
    return normal


def _levels(volume, air, bright, origin):
    """The flat horizontal levels where the air (a box's mask, its corner at voxel ``origin``) touches bright
    values: ``[(centre xyz, unit normal from the air into the fluid)]``, and the bright voxels beside them."""
    from scipy import ndimage

    touching = air & ndimage.binary_dilation(bright, iterations=2)  # across the partial-volume voxel between
    labels, n = ndimage.label(touching, structure=np.ones((3, 3, 3), bool))
    levels, seeds = [], np.zeros_like(air)
    for k in range(1, n + 1):
        part = labels == k
        pts = np.argwhere(part) + origin
        normal = _level(volume, pts)
        if normal is None:
            continue
        centre = volume.index_to_world(pts[:, ::-1].astype(float)).mean(axis=0)
        near = ndimage.binary_dilation(part, iterations=2) & bright
        below = volume.index_to_world((np.argwhere(near) + origin)[:, ::-1].astype(float)) - centre
        normal = normal * (np.sign(np.median(below @ normal)) or 1.0)  # from the air into the fluid
        levels.append((centre, normal))
        seeds |= near
    return levels, seeds


def add_tagged_fluid(volume, mask: np.ndarray, est):
    """``(mask, F)``: the air lumen ``mask`` with the tagged fluid under its levels (and the layer between)
    added, and the fluid's value ``F`` (data units); ``(mask, None)`` when there is none."""
    from scipy import ndimage

    from ...segment import region_grow
    from ._grow import _bbox

    if est.kind != "air" or not mask.any():
        return mask, None
    box = _bbox(mask, 3)
    origin = np.array([s.start for s in box])
    air = mask[box]
    data = np.asarray(volume.data[box], np.float32)
    shell = ndimage.binary_dilation(air, iterations=2) & ~air
    f = _bright_class(data[shell & (data > est.wall)], est.wall, est.threshold)
    if f is None:
        return mask, None
    t_fluid = 0.5 * (est.wall + f)
    levels, seeds = _levels(volume, air, data > t_fluid, origin)
    if not levels:
        return mask, None
    grown = region_grow(volume, (np.argwhere(seeds) + origin)[:, ::-1].astype(float), lo=t_fluid,
                        connectivity=6, space="voxel").data.astype(bool)
    idx = np.argwhere(grown)
    world = volume.index_to_world(idx[:, ::-1].astype(float))
    h = float(max(volume.spacing))
    under = np.zeros(len(idx), bool)
    for centre, normal in levels:
        under |= (world - centre) @ normal >= -h  # never more than a voxel above its level
    fluid = np.zeros_like(grown)
    fluid[tuple(idx[under].T)] = True
    fluid = ndimage.binary_propagation(fluid & _seeds_full(seeds, box, mask.shape), mask=fluid)
    out = mask | fluid
    box = _bbox(out, 2)
    a, w = mask[box], fluid[box]
    cube = np.ones((3, 3, 3), bool)
    out[box] |= ndimage.binary_dilation(a, cube) & ndimage.binary_dilation(w, cube)  # the layer between
    return out, float(np.median(volume.data[fluid]))


def _seeds_full(seeds, box, shape) -> np.ndarray:
    full = np.zeros(shape, bool)
    full[box] = seeds
    return full
