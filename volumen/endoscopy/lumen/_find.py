"""The lumen of a tubular organ: region growing from a seed inside it, over a range of CT values.

``lumen_mask(volume, seed, value_range)`` keeps the voxels whose value lies in
``value_range`` (air: ``(-1100, -500)`` HU; contrast: ``(150, 600)`` HU) and are
connected (faces, 6-connectivity) to the seed. A mask given by the caller is
accepted as is by :func:`as_lumen`.

The growing itself is :func:`volumen.segment.region_grow`; this module only finds
an in-range seed voxel near the user's point.

:func:`find_lumen` is what ``volumen fly`` uses: from a start (and an end)
point alone it checks both lie in the scan, finds the lumen's polarity, values
and wall from the start's neighbourhood (:func:`~volumen.endoscopy.estimate_lumen`),
grows from the start with explosion control and out to its partial-volume edge
(:mod:`._grow`), joins tagged fluid to an air lumen (:mod:`._fluid`), cuts thin
bridges to other structures (:func:`volumen.segment.cut_bridges`) and checks the
end lies in the same lumen. Each failure is a one-line
:class:`~volumen.errors.LumenError` naming the point, or the leak and the flags to
try (:data:`FLAGS`): a region that fills the scan (the point is in no lumen), a
growth that breaks through its wall into a larger region before it reaches the
end, points that join only through an opening narrower than the bridges cut.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ...core import mm_text, range_text, values_of
from ...errors import LumenError
from ._point_estimate import LumenEstimate, probe_lumen

__all__ = ["lumen_mask", "as_lumen", "find_lumen", "lumen_voxel", "AIR_RANGE", "CONTRAST_RANGE", "nearest_voxel",
           "FLAGS"]

#: what to try when a lumen leaks or is not found: the end of every such error message
#: steps past an explosion that only lengthen the lumen (:func:`~volumen.endoscopy._grow.continues`) grown on, at most
MAX_STEPS = 64
FLAGS = "pass --range LO,HI or --threshold T to set the lumen's values, or --lumen-mask FILE to give the lumen"

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
    from ...segment import region_grow

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
    return "(" + ", ".join(mm_text(v) for v in np.asarray(point, float)) + ") mm"


def lumen_voxel(volume, point, name: str = "start") -> tuple[int, int, int]:
    """The voxel ``(z, y, x)`` of a world ``point`` (mm); a point outside the scan raises LumenError naming it."""
    zyx = np.rint(volume.world_to_index(np.asarray(point, float))[::-1]).astype(int)
    if np.any(zyx < 0) or np.any(zyx >= volume.shape):
        lo, hi = volume.bounds()
        raise LumenError(f"the {name} point {_fmt(point)} lies outside the scan (x, y, z from {_fmt(lo)} "
                         f"to {_fmt(hi)})")
    return tuple(int(v) for v in zyx)


def _seed(volume, point, est) -> tuple[int, int, int]:
    """The lumen voxel to grow from: the in-range voxel nearest to ``point`` within three voxels."""
    lo, hi = est.value_range
    try:
        grown = lumen_mask(volume, point, (lo, hi), max_seed_distance=3.0 * max(volume.spacing))
    except ValueError:
        raise LumenError(f"the start point {_fmt(point)} is in no lumen: no value in "
                         f"{range_text(lo, hi, **values_of(volume))} next to it") from None
    return nearest_voxel(volume, grown, point)


def find_lumen(volume, start, end=None, *, kind: str = "auto", value_range=None, threshold=None,
               bridge_radius: float | None = None, max_fraction: float = 0.8) -> tuple[np.ndarray, LumenEstimate]:
    """The lumen holding ``start`` (and ``end``), found from the points alone.

    Parameters
    ----------
    volume : Volume
    start, end : (3,) float, world RAS+ mm
        Points inside the lumen (``end`` optional).
    kind : {"auto", "air", "contrast"}
        The lumen's polarity (``auto``: from the data around ``start``).
    value_range : (lo, hi) or None, data units
        Values grown as lumen; None: estimated (:func:`estimate_lumen`), then narrowed by explosion control.
    threshold : float or None, data units
        The wall threshold; None: estimated. The grown range ends at it unless ``value_range`` is given.
    bridge_radius : float or None, mm
        Bridges narrower than twice this are cut (0: none); None: the largest
        voxel spacing, at most half the lumen's radius at the points.
    max_fraction : float
        A region over this fraction of the scan is no lumen: the point sits in tissue, whose
        values join everything but the lumens. Air lumens open to the outside (a nose, 66 % of a head
        phantom's scan) stay below it.

    Returns
    -------
    mask : (nz, ny, nx) bool
    estimate : LumenEstimate
        With ``value_range`` the range grown (after explosion control) and ``tag`` the value of
        tagged fluid joined to an air lumen.

    Raises
    ------
    LumenError
        A point outside the scan or in no lumen, the end in a lumen not connected to the start's, or a
        leak that cannot be contained (the message names it and the flags to try).
    """
    from ...segment import cut_bridges
    from ._fluid import add_tagged_fluid
    from ._grow import continues, grow

    points = {"start": start} if end is None else {"start": start, "end": end}
    voxels = {name: lumen_voxel(volume, p, name) for name, p in points.items()}
    try:
        est, rays = probe_lumen(volume, voxels["start"], kind)
    except ValueError as exc:
        raise LumenError(f"the start point {_fmt(start)} is in no lumen: {exc}; {FLAGS}") from None
    if threshold is not None:
        est = est.with_threshold(threshold)
    if value_range is not None:
        est = est.with_range(value_range)
    seed = _seed(volume, start, est)
    growth = grow(volume, seed, est, lumen=rays.inside, max_fraction=max_fraction)
    for _ in range(MAX_STEPS):  # a lumen whose contrast fades grows on past steps that only lengthen it
        if end is None or not growth.exploded or _reaches(volume, growth.mask, end):
            break
        above = continues(volume, seed, est, growth)
        if above is None:
            break
        growth = grow(volume, seed, est, lumen=rays.inside, max_fraction=max_fraction, above=above)
    lo, hi = est.value_range
    if growth.fills:
        raise LumenError(f"the start point {_fmt(start)} is in no lumen: growing over "
                         f"{range_text(lo, hi, **values_of(volume))} from it "
                         f"fills more than {100 * max_fraction:.0f} % of the scan; {FLAGS}")
    est = est.with_range((lo, growth.threshold) if est.kind == "air" else (growth.threshold, hi))
    grown, tag = add_tagged_fluid(volume, growth.mask, est)
    est = replace(est, tag=tag)
    if end is not None:
        if growth.leak is not None and not _reaches(volume, grown, end):
            raise LumenError(_leak_message(volume, growth, points))
        _check_end(volume, grown, end, start, est.value_range)
    seeds = [nearest_voxel(volume, grown, p) for p in points.values()]
    radius = _bridge_radius(volume, grown, seeds) if bridge_radius is None else float(bridge_radius)
    cut = cut_bridges(grown, volume.spacing, seeds, radius)
    if all(cut[s] for s in seeds) and _connected(cut, seeds):
        grown = cut
    elif end is not None:
        raise LumenError(_neck_message(volume, grown, cut, points, radius))
    grown = _fill_holes(grown)
    if grown.mean() > max_fraction:
        raise LumenError(f"the start point {_fmt(start)} is in no lumen: growing over "
                         f"{range_text(lo, hi, **values_of(volume))} from it "
                         f"fills {100 * grown.mean():.0f} % of the scan; {FLAGS}")
    return grown, est


def _reaches(volume, grown: np.ndarray, point) -> bool:
    """Whether ``grown`` comes within three voxels (the largest spacing) of world ``point``."""
    near = nearest_voxel(volume, grown, point)
    gap = np.linalg.norm(volume.index_to_world(np.asarray(near[::-1], float)) - np.asarray(point, float))
    return bool(gap <= 3.0 * max(volume.spacing))


def _leak_message(volume, growth, points) -> str:
    """The growth from the start broke through its wall before it reached the end."""
    where = _fmt(volume.index_to_world(np.asarray(growth.leak[::-1], float)))
    size = growth.leak_voxels * float(np.prod(volume.spacing)) / 1000.0
    return (f"the lumen leaks: growing from the start point {_fmt(points['start'])} breaks through its wall into a "
            f"larger region (at {where}; {size:.3g} ml and more) before it reaches the end point "
            f"{_fmt(points['end'])}; {FLAGS}")


def _fill_holes(mask: np.ndarray) -> np.ndarray:
    """The enclosed cavities of ``mask`` filled (noise voxels of the lumen past its threshold)."""
    from scipy import ndimage

    from ._grow import _bbox

    box = _bbox(mask, 1)
    out = mask.copy()
    out[box] = ndimage.binary_fill_holes(mask[box])
    return out


def _neck_message(volume, grown, cut, points, radius) -> str:
    """What leaked: the start and end join only through a neck narrower than ``2 radius`` (removed by the cut)."""
    from scipy import ndimage

    removed = grown & ~cut
    labels, n = ndimage.label(removed, structure=np.ones((3, 3, 3), bool))
    where = ""
    if n:
        sizes = ndimage.sum(removed, labels, range(1, n + 1))
        k = int(np.argmax(sizes)) + 1
        centre = volume.index_to_world(np.argwhere(labels == k).mean(axis=0)[::-1])
        where = f" near {_fmt(centre)}"
    return (f"the lumen leaks: the start point {_fmt(points['start'])} and the end point {_fmt(points['end'])} join "
            f"only through an opening narrower than {2 * radius:.2g} mm{where} (a leak into a neighbouring region, or "
            f"a narrowing of the lumen); {FLAGS}")


def _check_end(volume, grown, end, start, rng) -> None:
    reach = 3.0 * max(volume.spacing)
    near = nearest_voxel(volume, grown, end)
    gap = np.linalg.norm(volume.index_to_world(np.asarray(near[::-1], float)) - np.asarray(end, float))
    if gap <= reach:
        return
    try:
        lumen_mask(volume, end, rng, max_seed_distance=reach)
    except ValueError:
        raise LumenError(f"the end point {_fmt(end)} is in no lumen: no value in "
                         f"{range_text(*rng, **values_of(volume))} next to it") from None
    raise LumenError(f"the end point {_fmt(end)} lies in a lumen that does not connect to the start point's "
                     f"{_fmt(start)}")


def _bridge_radius(volume, mask, seeds) -> float:
    from scipy import ndimage

    from ._grow import _bbox

    box = _bbox(mask, 1)
    dist = ndimage.distance_transform_edt(mask[box], sampling=tuple(float(s) for s in volume.spacing))
    at = [dist[tuple(int(v) - b.start for v, b in zip(s, box, strict=True))] for s in seeds]
    return float(min(max(volume.spacing), 0.5 * min(at)))


def _connected(mask, seeds) -> bool:
    from scipy import ndimage

    labels, _ = ndimage.label(mask)
    return len({int(labels[s]) for s in seeds}) == 1
