"""Cutting thin bridges out of a grown region: opening by reconstruction, keeping what holds the seeds.

Region growing over a value range leaks wherever a thin bridge of in-range
voxels (partial volume between a vessel and bone, two touching vessels) joins
the structure meant to another one. :func:`cut_bridges` removes such bridges:

1. ``core`` = the voxels farther than ``radius`` mm from the region's outside
   (Euclidean distance transform with the voxel spacing): an erosion by a ball,
   which breaks every bridge narrower than ``2 * radius``;
2. only the connected components of ``core`` (26-connectivity) that hold a
   seed are kept (a seed in no component of the core keeps the one nearest to it);
3. reconstruction: the region's voxels within ``radius`` (plus half a voxel)
   of the kept core, which restores the kept structure's own boundary and at
   most a ``radius``-long stub of each cut bridge.

A structure narrower than ``2 * radius`` everywhere (a stenosis) would break
too; the caller chooses the radius below the lumen's smallest radius.
"""

from __future__ import annotations

import numpy as np

__all__ = ["cut_bridges"]


def _box(mask: np.ndarray, pad: int) -> tuple[slice, ...]:
    idx = np.argwhere(mask)
    lo = np.maximum(idx.min(axis=0) - pad, 0)
    hi = np.minimum(idx.max(axis=0) + pad + 1, mask.shape)
    return tuple(slice(int(a), int(b)) for a, b in zip(lo, hi, strict=True))


def _nearest_label(labels: np.ndarray, point: np.ndarray, spacing: np.ndarray) -> int:
    lab = int(labels[tuple(point)])
    if lab:
        return lab
    idx = np.argwhere(labels > 0)
    k = int(np.argmin(np.linalg.norm((idx - point) * spacing, axis=1)))
    return int(labels[tuple(idx[k])])


def cut_bridges(mask, spacing, seeds, radius: float) -> np.ndarray:
    """The part of ``mask`` joined to ``seeds`` by paths at least ``2 * radius`` mm wide.

    Parameters
    ----------
    mask : (nz, ny, nx) bool
        The grown region ``[z, y, x]``.
    spacing : (3,) float, mm
        ``(dz, dy, dx)``.
    seeds : (n, 3) int
        Voxel indices ``(z, y, x)`` inside the structure to keep.
    radius : float, mm
        Half the width of the narrowest bridge kept; 0 returns ``mask`` unchanged.

    Returns
    -------
    (nz, ny, nx) bool
        A subset of ``mask``. When the erosion leaves nothing, ``mask`` itself.
    """
    from scipy import ndimage

    mask = np.asarray(mask, bool)
    if radius <= 0 or not mask.any():
        return mask
    sp = np.asarray(spacing, float)
    box = _box(mask, 1)
    sub = mask[box]
    core = ndimage.distance_transform_edt(sub, sampling=tuple(sp)) > radius
    if not core.any():
        return mask
    labels, _ = ndimage.label(core, structure=np.ones((3, 3, 3), bool))
    origin = np.array([s.start for s in box])
    keep = {_nearest_label(labels, np.asarray(s, int) - origin, sp) for s in np.atleast_2d(seeds)}
    kept = np.isin(labels, sorted(keep))
    near = ndimage.distance_transform_edt(~kept, sampling=tuple(sp)) <= radius + 0.5 * sp.max()
    out = np.zeros_like(mask)
    out[box] = sub & near
    return out
