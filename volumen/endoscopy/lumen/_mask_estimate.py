"""A segmentation's lumen and the values at its boundary: the polarity and the wall threshold the mask implies.

Given a lumen mask (TotalSegmentator, 3D Slicer...), the values are read from the
mask, not round a point: the lumen's value and noise are the median and the median
absolute deviation (x 1.4826) of the voxels deeper than a voxel and a half inside its
boundary (all inside when none is that deep), the wall's value the median of the
voxels within a voxel and a half outside it (where the boundary's neighbours are;
farther out, a thin wall gives way to what is behind it):

* the wall's value stands :data:`~volumen.endoscopy._polarity.SEPARATION` of the
  lumen's noise deviations from the lumen's: the lumen is air if darker, contrast if
  brighter, and the wall threshold lies half-way; the wall drawn is the data held to
  the mask (:class:`~volumen.endoscopy.LumenWall`);
* the voxels deep inside fall in two classes on either side of the wall's value (air
  over contrast-tagged fluid in a colon): an air lumen holding tagged fluid;
* it does not (a segmentation of a structure the data does not show apart from its
  surroundings): the wall drawn is the mask's own smoothed boundary.
"""

from __future__ import annotations

import numpy as np

from ._drawn_wall import LumenWall, signed_distance
from ._point_estimate import LUMEN_KINDS, SEPARATION, LumenEstimate

__all__ = ["estimate_from_mask"]


def _robust(values: np.ndarray) -> tuple[float, float]:
    med = float(np.median(values))
    return med, 1.4826 * float(np.median(np.abs(values - med)))


def _layers(volume, mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The data deeper than a voxel and a half inside the mask's boundary (every voxel inside when fewer than 8
    are that deep), and within a voxel and a half outside it."""
    from ._grow import _bbox

    box = _bbox(mask, 4)
    s = signed_distance(mask[box], volume.spacing) / float(max(volume.spacing))
    data = np.asarray(volume.data[box], np.float64)
    deep = data[s < -1.5]
    return deep if deep.size >= 8 else data[s < 0], data[(s > 0) & (s <= 1.5)]


def _two_sided(inside: np.ndarray, wall: float) -> tuple[float, float] | None:
    """``(air, tag)`` when the inside values fall in two classes either side of ``wall``, each standing
    :data:`SEPARATION` of its own noise deviations from it, else None."""
    from skimage.filters import threshold_otsu

    if inside.size < 16 or np.ptp(inside) <= 0:
        return None
    t = float(threshold_otsu(inside))
    low, high = inside[inside <= t], inside[inside > t]
    if min(low.size, high.size) < max(0.05 * inside.size, 8):
        return None
    (a, s_a), (f, s_f) = _robust(low), _robust(high)
    if a < wall - SEPARATION * s_a and f > wall + SEPARATION * s_f:
        return a, f
    return None


def estimate_from_mask(volume, mask: np.ndarray, kind: str = "auto") -> LumenWall:
    """The :class:`LumenWall` of a lumen ``mask`` (bool ``[z, y, x]``, the volume's grid) on ``volume``.

    Parameters
    ----------
    volume : Volume
    mask : (nz, ny, nx) bool
    kind : {"auto", "air", "contrast"}
        Forces the polarity; when the data says the other, the wall drawn is the mask's shape.

    Returns
    -------
    LumenWall
        Its estimate has the lumen's and the wall's values, the threshold half-way, ``tag`` for tagged
        fluid; ``shape_only`` when the data does not separate lumen and wall.
    """
    if kind not in LUMEN_KINDS:
        raise ValueError(f"lumen kind must be one of {', '.join(LUMEN_KINDS)}; got {kind!r}")
    mask = np.asarray(mask, bool)
    inside, outside = _layers(volume, mask)
    if inside.size == 0 or outside.size == 0:
        raise ValueError("the lumen mask has no inside or no outside to read values from")
    wall = _robust(outside)[0]
    lumen, noise = _robust(inside)
    tag = None
    two = _two_sided(inside, wall) if kind in ("auto", "air") else None
    if two is not None:
        lumen, tag = two
        noise = _robust(inside[inside <= 0.5 * (lumen + wall)])[1]
    noise = max(noise, 1e-3 * max(abs(lumen), 1.0))
    data_kind = "air" if lumen < wall else "contrast"
    kind = data_kind if kind == "auto" else kind
    shape_only = abs(wall - lumen) < SEPARATION * noise or kind != data_kind
    if shape_only:  # the drawn ramp still needs two values apart: the wall's put the separation away
        wall = lumen + (1.0 if kind == "air" else -1.0) * max(abs(wall - lumen), SEPARATION * noise)
    t = 0.5 * (lumen + wall)
    lo, hi = volume.value_range()
    rng = (min(lo, lumen), t) if kind == "air" else (t, max(hi, lumen))
    est = LumenEstimate(kind=kind, value_range=rng, threshold=t, spread=abs(wall - lumen), lumen=lumen, wall=wall,
                        noise=noise, tag=tag)
    return LumenWall(mask, est, shape_only)
