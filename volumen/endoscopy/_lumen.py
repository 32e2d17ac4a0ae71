"""The lumen of a tubular organ: region growing from a seed inside it, over a range of CT values.

``lumen_mask(volume, seed, value_range)`` keeps the voxels whose value lies in
``value_range`` (air: ``(-1100, -500)`` HU; contrast: ``(150, 600)`` HU) and are
connected (faces, 6-connectivity) to the seed. A mask given by the caller is
accepted as is by :func:`as_lumen`.

The growing itself is :func:`volumen.segment.region_grow`; this module only finds
an in-range seed voxel near the user's point.

:func:`find_lumen` is what ``volumen fly`` uses: from a start (and an end)
point alone it checks both lie in the scan, finds the lumen's polarity and
range (:func:`estimate_lumen`), grows from the start, refuses a region that
fills the scan (the point is in no lumen), cuts thin bridges to other
structures (:func:`volumen.segment.cut_bridges`) and checks the end lies in
the same lumen; each failure is a one-line :class:`~volumen.errors.LumenError`
naming the point.
"""

from __future__ import annotations

import numpy as np

from ..errors import LumenError
from ._polarity import LumenEstimate, estimate_lumen

__all__ = ["lumen_mask", "as_lumen", "find_lumen", "lumen_voxel", "AIR_RANGE", "CONTRAST_RANGE", "nearest_voxel"]

#: CT values (HU) of an air-filled lumen (colon, airway) and of a contrast-filled one (vessels)
AIR_RANGE = (-1100.0, -500.0)
CONTRAST_RANGE = (150.0, 600.0)


def nearest_voxel(volume, mask: np.ndarray, point) -> tuple[int, int, int]:
    """Index ``(z, y, x)`` of the voxel of ``mask`` nearest to a world ``point`` (xyz mm).

    Raises ValueError when the mask is empty.
    """
    ijk = volume.world_to_index(np.asarray(point, float))
    zyx = np.rint(ijk[::-1]).astype(int)
    if np.all(zyx >= 0) and np.all(zyx < mask.shape) and mask[tuple(zyx)]:
        return tuple(int(v) for v in zyx)
    idx = np.argwhere(mask)
    if idx.size == 0:
        raise ValueError("the lumen mask is empty")
    world = volume.index_to_world(idx[:, ::-1].astype(float))
    best = idx[int(np.argmin(np.linalg.norm(world - np.asarray(point, float), axis=1)))]
    return tuple(int(v) for v in best)


def lumen_mask(volume, seed, value_range: tuple[float, float] = AIR_RANGE, *, max_seed_distance: float = 10.0
               ) -> np.ndarray:
    """Region growing: the voxels in ``value_range`` connected to ``seed``.

    Parameters
    ----------
    volume : Volume
    seed : (3,) float, world RAS+ mm
        A point inside the lumen. When its voxel is out of range, the nearest
        in-range voxel within ``max_seed_distance`` mm is used.
    value_range : (lo, hi), data units
        Inclusive range of lumen values (``AIR_RANGE``, ``CONTRAST_RANGE``).
    max_seed_distance : float, mm

    Returns
    -------
    mask : (nz, ny, nx) bool
        The lumen, ``[z, y, x]``.

    Raises
    ------
    ValueError
        When no in-range voxel lies within ``max_seed_distance`` of the seed.
    """
    from ..segment import region_grow

    lo, hi = (float(v) for v in value_range)
    if not hi >= lo:
        raise ValueError(f"value_range must be (lo, hi) with lo <= hi, got {value_range}")
    seed = np.asarray(seed, float).reshape(3)
    # look for the seed voxel in a small box around the seed only
    ijk = volume.world_to_index(seed)
    reach = max_seed_distance / np.array(volume.spacing)[::-1]  # voxels along i, j, k
    lo_i = np.maximum(np.floor(ijk - reach).astype(int), 0)
    hi_i = np.minimum(np.ceil(ijk + reach).astype(int), np.array(volume.shape[::-1]) - 1)
    if np.any(hi_i < lo_i):
        raise ValueError(f"seed {seed.tolist()} mm lies outside the volume")
    box = volume.data[lo_i[2]:hi_i[2] + 1, lo_i[1]:hi_i[1] + 1, lo_i[0]:hi_i[0] + 1]
    cand = np.argwhere((box >= lo) & (box <= hi))
    if cand.size == 0:
        raise ValueError(f"no voxel with a value in [{lo:g}, {hi:g}] within {max_seed_distance} mm of the seed "
                         f"{seed.tolist()} mm: is the seed inside the lumen?")
    world = volume.index_to_world((cand[:, ::-1] + lo_i).astype(float))
    dist = np.linalg.norm(world - seed, axis=1)
    if dist.min() > max_seed_distance:
        raise ValueError(f"no lumen voxel within {max_seed_distance} mm of the seed {seed.tolist()} mm")
    start_ijk = (cand[int(np.argmin(dist))] + lo_i[::-1])[::-1].astype(float)
    grown = region_grow(volume, start_ijk, lo=lo, hi=hi, connectivity=6, space="voxel")
    return grown.data.astype(bool)


def as_lumen(volume, mask) -> np.ndarray:
    """Check a caller's lumen mask against the volume: bool ``[z, y, x]`` of the volume's shape."""
    m = np.asarray(mask)
    if m.shape != volume.shape:
        raise ValueError(f"lumen mask shape {m.shape} differs from the volume's {volume.shape}")
    m = m.astype(bool, copy=False)
    if not m.any():
        raise ValueError("the lumen mask is empty")
    return m


def _fmt(point) -> str:
    return "(" + ", ".join(f"{v:g}" for v in np.asarray(point, float)) + ") mm"


def lumen_voxel(volume, point, name: str = "start") -> tuple[int, int, int]:
    """The voxel ``(z, y, x)`` of a world ``point`` (mm); a point outside the scan raises LumenError naming it."""
    zyx = np.rint(volume.world_to_index(np.asarray(point, float))[::-1]).astype(int)
    if np.any(zyx < 0) or np.any(zyx >= volume.shape):
        lo, hi = volume.bounds()
        raise LumenError(f"the {name} point {_fmt(point)} lies outside the scan (x, y, z from {_fmt(lo)} "
                         f"to {_fmt(hi)})")
    return tuple(int(v) for v in zyx)


def find_lumen(volume, start, end=None, *, kind: str = "auto", value_range=None, bridge_radius: float | None = None,
               max_fraction: float = 0.8) -> tuple[np.ndarray, LumenEstimate]:
    """The lumen holding ``start`` (and ``end``), found from the points alone.

    Parameters
    ----------
    volume : Volume
    start, end : (3,) float, world RAS+ mm
        Points inside the lumen (``end`` optional).
    kind : {"auto", "air", "contrast"}
        The lumen's polarity (``auto``: from the data around ``start``).
    value_range : (lo, hi) or None, data units
        Values grown as lumen; None: estimated (:func:`estimate_lumen`).
    bridge_radius : float or None, mm
        Bridges narrower than twice this are cut (0: none); None: the largest
        voxel spacing, at most half the lumen's radius at the points.
    max_fraction : float
        A region (bridges cut) over this fraction of the scan is no lumen: the point sits in tissue, whose
        values join everything but the lumens. Air lumens open to the outside (a nose, 66 % of a head
        phantom's scan) stay below it.

    Returns
    -------
    mask : (nz, ny, nx) bool
    estimate : LumenEstimate
        With ``value_range`` replaced by the one used.

    Raises
    ------
    LumenError
        A point outside the scan or in no lumen, or the end in a lumen not connected to the start's.
    """
    from ..segment import cut_bridges

    points = {"start": start} if end is None else {"start": start, "end": end}
    voxels = {name: lumen_voxel(volume, p, name) for name, p in points.items()}
    try:
        est = estimate_lumen(volume, voxels["start"], kind)
    except ValueError as exc:
        raise LumenError(f"the start point {_fmt(start)} is in no lumen: {exc}") from None
    if value_range is not None:
        est = est.with_range(value_range)
    lo, hi = est.value_range
    try:
        grown = lumen_mask(volume, start, (lo, hi), max_seed_distance=3.0 * max(volume.spacing))
    except ValueError:
        raise LumenError(f"the start point {_fmt(start)} is in no lumen: no value in {lo:g}..{hi:g} "
                         "next to it") from None
    if end is not None:
        _check_end(volume, grown, end, start, (lo, hi))
    seeds = [nearest_voxel(volume, grown, p) for p in points.values()]
    radius = _bridge_radius(volume, grown, seeds) if bridge_radius is None else float(bridge_radius)
    cut = cut_bridges(grown, volume.spacing, seeds, radius)
    if all(cut[s] for s in seeds) and _connected(cut, seeds):
        grown = cut
    if grown.mean() > max_fraction:
        raise LumenError(f"the start point {_fmt(start)} is in no lumen: growing over {lo:g}..{hi:g} from it "
                         f"fills {100 * grown.mean():.0f} % of the scan")
    return grown, est


def _check_end(volume, grown, end, start, rng) -> None:
    reach = 3.0 * max(volume.spacing)
    near = nearest_voxel(volume, grown, end)
    gap = np.linalg.norm(volume.index_to_world(np.asarray(near[::-1], float)) - np.asarray(end, float))
    if gap <= reach:
        return
    try:
        lumen_mask(volume, end, rng, max_seed_distance=reach)
    except ValueError:
        raise LumenError(f"the end point {_fmt(end)} is in no lumen: no value in {rng[0]:g}..{rng[1]:g} "
                         "next to it") from None
    raise LumenError(f"the end point {_fmt(end)} lies in a lumen that does not connect to the start point's "
                     f"{_fmt(start)}")


def _bridge_radius(volume, mask, seeds) -> float:
    from scipy import ndimage

    dist = ndimage.distance_transform_edt(mask, sampling=tuple(float(s) for s in volume.spacing))
    return float(min(max(volume.spacing), 0.5 * min(dist[s] for s in seeds)))


def _connected(mask, seeds) -> bool:
    from scipy import ndimage

    labels, _ = ndimage.label(mask)
    return len({int(labels[s]) for s in seeds}) == 1
