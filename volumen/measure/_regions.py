"""A region's statistics over the scan's voxels (never over the displayed picture).

The voxels of a region are those whose box the plane cuts and whose centre, projected onto the plane, lies inside
the shape. A voxel's box is cut by the plane where its centre lies within half the box's width along the normal,
``h = 1/2 sum_a |n . e_a| s_a`` (``e_a`` the voxel axes' directions, ``s_a`` their spacings): on a slice view's plane
(:func:`slice_plane`) that is the one slice of voxels shown, on an oblique plane the voxels it passes through.
Only the index box around the region is visited, so a small region on a large scan costs little.
"""

from __future__ import annotations

import numpy as np

from ..core import hu_offset, is_chunked
from ..errors import OutsideVolumeError
from ._model import RegionStats, Scan
from ._plane_shapes import Plane

__all__ = ["roi_stats", "region_voxels"]


def _half_width(volume, plane: Plane) -> float:
    """Half the width of a voxel's box along the plane's normal, mm."""
    cols = volume.affine[:3, :3]
    return 0.5 * float(np.abs(plane.normal @ cols).sum())


def _index_box(volume, plane: Plane, shape) -> tuple[slice, slice, slice] | None:
    """The ``[z, y, x]`` index box holding every voxel the region can take, None where it misses the volume."""
    (s0, t0), (s1, t1) = shape.bounds()
    h = _half_width(volume, plane)
    corners = plane.to_world(np.array([[s, t] for s in (s0, s1) for t in (t0, t1)]))
    corners = np.concatenate([corners + plane.normal * h, corners - plane.normal * h])
    ijk = volume.world_to_index(corners)
    lo = np.maximum(np.floor(ijk.min(axis=0)).astype(int), 0)
    hi = np.minimum(np.ceil(ijk.max(axis=0)).astype(int), np.array(volume.shape[:3][::-1]) - 1)
    if np.any(hi < lo):
        return None
    return tuple(slice(lo[a], hi[a] + 1) for a in (2, 1, 0))


def region_voxels(volume, plane: Plane, shape) -> tuple[tuple[slice, slice, slice], np.ndarray] | None:
    """``(box, mask)``: the index box (``[z, y, x]`` slices) and the boolean mask, over it, of the region's voxels;
    None where no voxel of the volume is in the region."""
    box = _index_box(volume, plane, shape)
    if box is None:
        return None
    h = _half_width(volume, plane) * (1 + 1e-9)
    j, i = np.meshgrid(np.arange(box[1].start, box[1].stop), np.arange(box[2].start, box[2].stop), indexing="ij")
    mask = np.zeros(tuple(b.stop - b.start for b in box), bool)
    for n, k in enumerate(range(box[0].start, box[0].stop)):  # a slice at a time: an oblique plane's box is large
        st, dist = plane.to_plane(volume.index_to_world(np.stack([i, j, np.full_like(i, k)], axis=-1)))
        mask[n] = (np.abs(dist) <= h) & shape.contains(st)
    return (box, mask) if mask.any() else None


def _outside(volume, plane: Plane, shape) -> OutsideVolumeError:
    centre = plane.to_world(shape.bounds().mean(axis=0))
    lo, hi = volume.bounds()
    where = volume.meta.get("source") or volume.name or "the volume"
    return OutsideVolumeError(
        f"the {shape.kind} centred at ({', '.join(f'{c:.1f}' for c in centre)}) mm holds no voxel of {where} "
        f"(its voxel centres span ({', '.join(f'{c:.1f}' for c in lo)})..({', '.join(f'{c:.1f}' for c in hi)}) mm)")


def roi_stats(volume, plane: Plane, shape, label: str = "") -> RegionStats:
    """The statistics of ``volume``'s voxels in ``shape`` on ``plane``.

    Parameters
    ----------
    volume : Volume
        The scan (a scalar volume); a CT's values are reported in HU (stored values less ``core.hu_offset``).
    plane : Plane
        The slice plane, world RAS+ mm (:func:`slice_plane` for a slice view's plane).
    shape : Ellipse, Rectangle or Polygon
        The region in the plane's coordinates, mm.

    Returns
    -------
    RegionStats
        mean, SD (population), min, max, median in the scan's units, the shape's area in mm², the voxel count.

    Raises
    ------
    OutsideVolumeError
        No voxel of the volume lies in the region.
    """
    if volume.is_color:
        raise ValueError("region statistics need a scalar volume; this one is colour (RGB)")
    found = region_voxels(volume, plane, shape)
    if found is None:
        raise _outside(volume, plane, shape)
    box, mask = found
    block = volume.data[box]
    values = np.asarray(block if not is_chunked(block) else block[...], dtype=np.float64)[mask]
    offset = hu_offset(volume)
    units = volume.units or ""
    if offset is not None:
        values = values - offset
        units = "HU"
    return RegionStats(plane=plane, shape=shape, mean=float(values.mean()), sd=float(values.std()),
                  min=float(values.min()), max=float(values.max()), median=float(np.median(values)),
                  area_mm2=shape.area, voxels=int(values.size), units=units, scan=Scan.of(volume), label=label)
