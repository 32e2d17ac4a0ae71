"""Growing a lumen from a seed with explosion control, then out to its partial-volume boundary.

Region growing at the wall threshold leaks wherever the wall is thinner than the
scanner's blur: a bronchus's one-voxel wall reads a few hundred HU below the soft
tissue it is, so air inside and air-like lung outside join through it (the classic
leak of virtual bronchoscopy). :func:`grow` grows in two stages:

1. **Explosion control** (the adaptive threshold of airway segmentation): the
   threshold is raised from the lumen's own values (three noise standard deviations
   past its value) toward the wall threshold in steps of one noise standard deviation,
   and the grown volume is watched (one compiled priority flood,
   :func:`~volumen.endoscopy._grow_kernel.flood_levels`). Inside a lumen a step adds a
   thin shell of partial-volume voxels, a few per cent; a step that more than doubles
   the volume has broken into a region beyond the wall, and growing stops at the step
   before. The region is grown (6-connected) at that threshold.
2. **The partial-volume band**: up to two voxels are added round it (6-connected
   dilation), each only where the data is on the lumen's side of the half-way value
   between the *local* lumen value and the wall's. The local lumen value is the lumen's
   data smoothed over a few voxels (a normalised convolution), so a lumen whose contrast
   fades along its length (bolus washout) keeps its own half-way boundary. Two voxels
   cannot carry a leak past a wall: at most a voxel of what lies behind a wall thinner
   than a voxel is taken.

A lumen whose contrast fades along it (bolus washout) lengthens by a stretch of tube at
each step, which can outnumber its outer shell: :func:`continues` tells such a step (at
most doubling the volume, nothing added wider than the region before it) from a break
into a larger region, and :func:`~volumen.endoscopy.find_lumen` grows on past it
(``above``) while the end point is not reached.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Growth", "grow", "continues", "BAND", "EXPLOSION"]

#: a threshold step that multiplies the grown volume by more than this is an explosion
EXPLOSION = 2.0
#: voxels of partial-volume band added round the grown region
BAND = 2


@dataclass(frozen=True, eq=False)
class Growth:
    """A grown lumen.

    Attributes
    ----------
    mask : (nz, ny, nx) bool
    threshold : float, data units
        The threshold grown at (before the partial-volume band).
    exploded : bool
        Whether raising the threshold further would have broken through the wall.
    fills : bool
        Whether the region was larger than allowed at the lumen's own values already.
    leak : (3,) int or None
        A voxel ``(z, y, x)`` of the region the growth would have broken into (None when none).
    leak_voxels : int
        How many voxels that next step had taken when it was stopped (at least).
    step : float, data units
        Between the thresholds checked (the lumen's noise).
    """

    mask: np.ndarray
    threshold: float
    exploded: bool
    fills: bool
    leak: tuple[int, int, int] | None = None
    leak_voxels: int = 0
    step: float = 0.0


def _bbox(mask: np.ndarray, pad: int) -> tuple[slice, ...]:
    idx = np.argwhere(mask)
    lo = np.maximum(idx.min(axis=0) - pad, 0)
    hi = np.minimum(idx.max(axis=0) + pad + 1, mask.shape)
    return tuple(slice(int(a), int(b)) for a, b in zip(lo, hi, strict=True))


def _band(volume, mask: np.ndarray, est) -> np.ndarray:
    """``mask`` with up to :data:`BAND` voxels of partial-volume band added (see the module docstring)."""
    from scipy import ndimage

    box = _bbox(mask, BAND + 1)
    sub = mask[box]
    data = np.asarray(volume.data[box], np.float32)
    sigma = 3.0 * float(max(volume.spacing)) / np.asarray(volume.spacing, float)  # a few voxels, in voxels
    weight = ndimage.gaussian_filter(sub.astype(np.float32), sigma, mode="constant")
    local = ndimage.gaussian_filter(np.where(sub, data, 0.0).astype(np.float32), sigma, mode="constant")
    lumen = np.where(weight > 1e-3, local / np.maximum(weight, 1e-3), est.lumen)
    inside = est.sign * data <= est.sign * 0.5 * (lumen + est.wall)
    out = sub.copy()
    for _ in range(BAND):
        out |= ndimage.binary_dilation(out) & inside
    full = mask.copy()
    full[box] = out
    return full


def _region(volume, seed, est, threshold: float) -> np.ndarray:
    """The 6-connected region from voxel ``seed`` of the values on the lumen's side of ``threshold``."""
    from ...segment import region_grow

    lo, hi = est.value_range
    rng = (lo, threshold) if est.sign > 0 else (threshold, hi)
    return region_grow(volume, np.asarray([seed[::-1]], float), lo=rng[0], hi=rng[1], connectivity=6,
                       space="voxel").data.astype(bool)


def continues(volume, seed, est, growth: Growth) -> float | None:
    """The threshold one step past an explosion (data units) when that step only lengthens the lumen, else None.

    The step continues the lumen when it at most doubles the region (:data:`EXPLOSION`) and nothing it adds
    lies deeper inside the grown region than the region before it reaches (the largest distance to the
    region's boundary, mm): the next stretch of a tube whose contrast fades, not a break into a wider
    region (the lung behind a bronchus's wall, a pocket through its neck: many times the volume).
    """
    from scipy import ndimage

    if not growth.exploded or growth.step <= 0:
        return None
    nxt = growth.threshold + est.sign * growth.step
    before, after = _region(volume, seed, est, growth.threshold), _region(volume, seed, est, nxt)
    if after.sum() > EXPLOSION * before.sum():
        return None
    box = _bbox(after, 1)
    depth = ndimage.distance_transform_edt(after[box], sampling=tuple(float(s) for s in volume.spacing))
    added = after[box] & ~before[box]
    return nxt if not added.any() or depth[added].max() <= depth[before[box]].max() else None


def grow(volume, seed, est, *, lumen=None, max_fraction: float = 0.8, above: float | None = None) -> Growth:
    """Grow the lumen of estimate ``est`` from voxel ``seed`` (``(z, y, x)``), see the module docstring.

    ``lumen`` (``(m, 3)`` int ``(z, y, x)``): voxels known to be lumen (those the rays from the
    seed crossed, :attr:`RayProbe.inside`); explosion control begins once the region holds them
    all, so a lumen whose values vary more than its noise (uneven contrast) is whole before
    its volume is watched. The growth never passes the estimate's value range (its wall-side
    end); ``max_fraction`` of the scan's voxels at the lumen's own values already means the
    seed is in no lumen (``fills``). ``above`` (data units): explosion control watches only the
    thresholds past this one (a step found to continue the lumen, :func:`continues`).
    """
    from ._grow_kernel import Flood, flood_levels

    sign = est.sign
    lo, hi = est.value_range
    u_max = hi if sign > 0 else -lo
    u0 = min(sign * est.lumen + 3.0 * est.noise, u_max)
    if above is not None:
        u0 = min(max(u0, sign * float(above)), u_max)
    step = max(est.noise, 1e-6 * max(abs(u_max - u0), 1.0))
    visited = np.zeros(volume.shape, np.uint8)
    out = np.zeros(5)
    seed_flat = int(np.ravel_multi_index(tuple(int(v) for v in seed), volume.shape))
    data = volume.data if volume.data.flags.c_contiguous else np.ascontiguousarray(volume.data)
    targets = np.zeros(0, np.int64)
    if lumen is not None and len(lumen):
        zyx = np.asarray(lumen, np.int64)
        zyx = zyx[sign * np.asarray(data[tuple(zyx.T)], float) <= u_max]
        targets = np.unique(np.ravel_multi_index(tuple(zyx.T), volume.shape)).astype(np.int64)
    settings = Flood(float(sign), float(u0), float(u_max), float(step), EXPLOSION, int(max_fraction * visited.size))
    flood_levels(data, seed_flat, targets, settings, visited, out)
    del visited
    u_grow, reason = float(out[0]), int(out[2])
    t = sign * u_grow
    mask = _region(volume, seed, est, t)
    if reason != 2:
        mask = _band(volume, mask, est)
    leak = None if out[3] < 0 else tuple(int(v) for v in np.unravel_index(int(out[3]), volume.shape))
    return Growth(mask, t, reason == 1, reason == 2, leak, int(out[4]), float(step))
