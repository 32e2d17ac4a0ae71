"""The lumen of a tubular organ: region growing from a seed inside it, over a range of CT values.

``lumen_mask(volume, seed, value_range)`` keeps the voxels whose value lies in
``value_range`` (air: ``(-1100, -500)`` HU; contrast: ``(150, 600)`` HU) and are
connected (faces, 6-connectivity) to the seed. A mask given by the caller is
accepted as is by :func:`as_lumen`.

The growing itself is :func:`volumen.segment.region_grow`; this module only finds
an in-range seed voxel near the user's point.
"""

from __future__ import annotations

import numpy as np

__all__ = ["lumen_mask", "as_lumen", "AIR_RANGE", "CONTRAST_RANGE", "nearest_voxel"]

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
