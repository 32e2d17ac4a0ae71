"""Which way round a lumen is, found from the data: air (darker than its wall) or contrast (brighter).

:func:`estimate_lumen` looks at a ball around a point inside the lumen and
splits its values in two classes with Otsu's threshold. The point's own value
(median of its 3x3x3 neighbourhood) says on which side the lumen is:

* above the split: a contrast-filled lumen (vessels), the wall where the data
  falls below the threshold;
* below it: an air-filled lumen (colon, airways), the wall where the data rises.

When the point's own class splits again in the same way (air | tissue |
contrast around a vessel next to a lung), the split inside it is the wall.
The ball grows (10, 20, 40, 80 mm) until each class holds at least 5 % of its
voxels and the classes stand apart (the distance between their means at least
``SEPARATION`` times their pooled standard deviation: noise split in two by
Otsu gives about 2.7), so a point deep in a wide lumen still sees its wall. The lumen's value
range runs from the threshold to the far end of the lumen's class, widened by
the class's own extent so noise in the lumen stays inside it.

The resulting :class:`LumenEstimate` gives the wall threshold for growing,
for the isosurface and for collisions, and the endoscopy transfer function
(transparent lumen, opaque wall) in the scan's own units.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

__all__ = ["LumenEstimate", "estimate_lumen", "LUMEN_KINDS"]

LUMEN_KINDS = ("auto", "air", "contrast")
#: how far apart (in pooled standard deviations) lumen and wall values must be
SEPARATION = 4.0


@dataclass(frozen=True)
class LumenEstimate:
    """A lumen's polarity, value range and wall threshold, in the scan's units.

    Attributes
    ----------
    kind : {"air", "contrast"}
        ``air``: the lumen is darker than the wall; ``contrast``: brighter.
    value_range : (lo, hi), data units
        Values grown as lumen (inclusive).
    threshold : float, data units
        The wall: half-way between the lumen's and the wall's values (Otsu).
    spread : float, data units
        Distance between the two classes' medians (sets the transfer function's ramp).
    """

    kind: Literal["air", "contrast"]
    value_range: tuple[float, float]
    threshold: float
    spread: float

    @property
    def lumen_side(self) -> Literal["below", "above"]:
        """Which side of the threshold the lumen is on (for :meth:`WallField.from_threshold`)."""
        return "below" if self.kind == "air" else "above"

    def wall(self, volume):
        """The :class:`WallField` at the threshold, the lumen on its side."""
        from ._wall import WallField

        return WallField.from_threshold(volume, self.threshold, self.lumen_side)

    def transfer(self):
        """Endoscopy transfer function: the lumen transparent, the wall opaque from the threshold on.

        Opacity ramps over ``0.15 * spread`` either side of the threshold; the wall's
        colour goes from dark red at the threshold to pale pink deeper in the wall.
        """
        from ..core import TransferFunction

        t, w = self.threshold, max(0.15 * self.spread, 1e-3)
        sign = 1.0 if self.kind == "air" else -1.0  # direction from the lumen into the wall
        wall = [t + sign * w, t + sign * 4 * w, t + sign * 10 * w]
        lumen = t - sign * w
        colors = [(lumen, 0.7, 0.25, 0.2), (wall[0], 0.85, 0.4, 0.35), (wall[1], 0.95, 0.65, 0.55),
                  (wall[2], 1.0, 0.85, 0.75)]
        opacity = [(lumen, 0.0), (wall[0], 1.0)]
        colors.sort(key=lambda c: c[0])
        opacity.sort(key=lambda c: c[0])
        return TransferFunction(color=tuple(colors), opacity=tuple(opacity), name=f"endo-{self.kind}-auto")

    def with_range(self, value_range) -> LumenEstimate:
        """The same estimate with another lumen value range ``(lo, hi)`` (data units)."""
        lo, hi = (float(v) for v in value_range)
        if not hi >= lo:
            raise ValueError(f"the lumen's value range must be (lo, hi) with lo <= hi, got {value_range}")
        return LumenEstimate(self.kind, (lo, hi), self.threshold, self.spread)

    def describe(self) -> str:
        """One line for the user: what was chosen."""
        lo, hi = self.value_range
        return (f"lumen: {self.kind} (the lumen is {'darker' if self.kind == 'air' else 'brighter'} than its wall), "
                f"values {lo:g}..{hi:g}, wall threshold {self.threshold:g}")


def _ball(volume, zyx, radius: float) -> np.ndarray:
    sp = np.asarray(volume.spacing, float)
    r = np.ceil(radius / sp).astype(int)
    lo = np.maximum(np.asarray(zyx) - r, 0)
    hi = np.minimum(np.asarray(zyx) + r + 1, volume.shape)
    box = volume.data[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]]
    grids = np.ogrid[tuple(slice(int(a), int(b)) for a, b in zip(lo, hi, strict=True))]
    d2 = sum(((g - c) * s) ** 2 for g, c, s in zip(grids, zyx, sp, strict=True))
    return np.asarray(box[d2 <= radius * radius], np.float64)


def _split(vals: np.ndarray) -> tuple[float, np.ndarray, np.ndarray] | None:
    """Otsu's split of ``vals`` when its two classes are distinct (sizes and separation), else None."""
    from skimage.filters import threshold_otsu

    if vals.size < 8 or np.ptp(vals) <= 0:
        return None
    t = float(threshold_otsu(vals))
    low, high = vals[vals <= t], vals[vals > t]
    if min(low.size, high.size) < max(0.05 * vals.size, 2):
        return None
    pooled = np.sqrt(0.5 * (low.var() + high.var()))
    return (t, low, high) if high.mean() - low.mean() >= SEPARATION * pooled else None


def _classes(volume, zyx, here: float) -> tuple[float, np.ndarray, np.ndarray]:
    for radius in (10.0, 20.0, 40.0, 80.0):
        split = _split(_ball(volume, zyx, radius))
        while split is not None:  # descend while the point's own class splits again (air | tissue | contrast)
            t, low, high = split
            inner = _split(high if here > t else low)
            if inner is None or inner[0] == t:
                return split
            split = inner
    raise ValueError("no wall within 80 mm of it: its neighbourhood holds no two distinct classes of values")


def estimate_lumen(volume, zyx, kind: str = "auto") -> LumenEstimate:
    """Polarity, value range and wall threshold of the lumen around voxel ``zyx``.

    Parameters
    ----------
    volume : Volume
    zyx : (3,) int
        A voxel inside the lumen, ``(z, y, x)``.
    kind : {"auto", "air", "contrast"}
        ``auto`` decides from the voxel's value; the others force the polarity
        (the threshold and range still come from the data).

    Returns
    -------
    LumenEstimate
    """
    if kind not in LUMEN_KINDS:
        raise ValueError(f"lumen kind must be one of {', '.join(LUMEN_KINDS)}; got {kind!r}")
    z, y, x = (int(v) for v in zyx)
    here = float(np.median(volume.data[max(z - 1, 0):z + 2, max(y - 1, 0):y + 2, max(x - 1, 0):x + 2]))
    t, low, high = _classes(volume, zyx, here)
    if kind == "auto":
        kind = "contrast" if here > t else "air"
    spread = float(np.median(high) - np.median(low))
    if kind == "contrast":
        top = float(high.max())
        rng = (t, top + (top - t))
    else:
        bottom = float(low.min())
        rng = (bottom - (t - bottom), t)
    return LumenEstimate(kind=kind, value_range=rng, threshold=t, spread=spread)
