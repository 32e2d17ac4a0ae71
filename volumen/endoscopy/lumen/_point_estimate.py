"""A lumen's values, its wall's and which way round they are, found from the data around a point inside it.

:func:`estimate_lumen` works from the point's own neighbourhood outward, so that
neighbours of other classes (a lung beside the aorta, the tagged fluid in a
colon, bone) cannot take the place of the wall:

1. **The lumen's class**: the densest half of the values in a small ball round the
   point, two voxels in radius (their shortest half-range, the "shorth"): its median is
   the lumen's value and its width the noise (the middle half of a Gaussian spans 1.349
   standard deviations). A point near the wall sees wall voxels in the ball, all on one
   side of the lumen's values; up to half of the ball may be wall and the densest half
   is still the lumen's.
2. **Rays** (:func:`~volumen.endoscopy._rays.cast_rays`): from the point, in 162
   directions out to 50 mm (100 mm when none meets anything), each ray leaves the
   lumen where the data departs from the lumen's value by three noise standard
   deviations, and meets the value where that edge levels off.
3. **Polarity**: most rays meet brighter values round an air lumen (colon,
   airways) and darker ones round a contrast-filled lumen (vessels).
4. **The wall's class** is what the rays meet nearest in value to the lumen: the
   quartile of the met values on the lumen's side. A lumen is bounded by its own
   wall (soft tissue) all round; what lies beyond a wall too thin to show (a lung
   three millimetres from the aorta, the air of a lung round a bronchus) is met by
   some rays only, and farther from the lumen's value than the wall is; the
   quartile stands for the wall while up to three rays in four meet something else.
5. The lumen's and the wall's values must stand :data:`SEPARATION` noise deviations
   apart (a point in tissue has neighbours of other values too, but no wall round it
   that stands out of its own texture).
6. **Settled at the vessel's scale** (:func:`probe_lumen`): the lumen's value and spread are read again
   from the hundreds of voxels the rays crossed inside it, and the rays cast again, while that spread grows
   (by at most :data:`SETTLE_GROWTH` a step); the last estimate that passes 5. is kept. Contrast layered
   across a vessel or mixed with unopacified blood is the lumen's own variation, which the ball of 1. does
   not show: read as noise, the rays left the lumen at its darker layers and took them for its wall. A point
   refused so, whose rays meet one class in most directions (a pocket of unopacified blood), is estimated
   from that class, and kept when its own value lies in that lumen's range.
7. **The wall threshold** lies half-way between the lumen's and the wall's values:
   where a blurred edge between the two is crossed, the partial-volume boundary.
   The lumen's values run from the threshold to the scan's far end.

The resulting :class:`LumenEstimate` gives the wall threshold for growing, for
the isosurface and for collisions, and the endoscopy transfer function
(transparent lumen, opaque wall) in the scan's own units. It is printed by
``volumen fly`` (:meth:`LumenEstimate.describe`).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, replace
from typing import Literal

import numpy as np

from ...core import value_text, values_of

__all__ = ["LumenEstimate", "estimate_lumen", "probe_lumen", "LUMEN_KINDS", "lumen_class"]

LUMEN_KINDS = ("auto", "air", "contrast")
#: how far apart (in pooled standard deviations) lumen and wall values must be to tell them apart: a threshold
#: half-way puts 2.3 % of either class on the wrong side
SEPARATION = 4.0
#: the rays' tolerance: a sample more than this many noise standard deviations from the lumen's value has left
#: it (0.3 % of the lumen's own samples are farther, and fewer still on the smoothed copy the rays read)
DEPARTURE = 3.0
#: of the values met, the quartile nearest the lumen's stands for its wall (see the module docstring)
WALL_QUANTILE = 0.25
REACH = (50.0, 100.0)  # mm: the rays' reach, tried in turn
#: the lumen's value and spread are read again from the voxels the rays crossed inside it, and the rays cast
#: again with that spread, at most this many times (until the spread grows no more)
SETTLE = 4
#: ... when they crossed this many voxels at least
SETTLE_VOXELS = 200
#: ... and while the spread grows by at most this factor a step
SETTLE_GROWTH = 2.0
#: a refused point whose rays meet one class in more than this share of directions is a pocket inside it
POCKET = 0.5


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
        The wall: half-way between the lumen's and the wall's values.
    spread : float, data units
        Distance between the lumen's and the wall's values (sets the transfer function's ramp).
    lumen, wall : float or None, data units
        The two classes' values (None when not estimated).
    noise : float, data units
        The lumen's noise standard deviation.
    tag : float or None, data units
        The value of contrast-tagged fluid lying in an air lumen (part of the lumen), None when none.
    """

    kind: Literal["air", "contrast"]
    value_range: tuple[float, float]
    threshold: float
    spread: float
    lumen: float | None = None
    wall: float | None = None
    noise: float = 0.0
    tag: float | None = None

    @property
    def sign(self) -> float:
        """+1 for an air lumen (the wall brighter), -1 for contrast: data x sign grows from lumen into wall."""
        return 1.0 if self.kind == "air" else -1.0

    @property
    def lumen_side(self) -> Literal["below", "above"]:
        """Which side of the threshold the lumen is on (for :meth:`WallField.from_threshold`)."""
        return "below" if self.kind == "air" else "above"

    def wall_field(self, volume):
        """The :class:`WallField` at the threshold, the lumen on its side."""
        from ..wall._field import WallField

        return WallField.from_threshold(volume, self.threshold, self.lumen_side)


    def transfer(self):
        """Endoscopy transfer function: the lumen transparent, the wall opaque from the threshold on.

        Opacity ramps over ``0.15 * spread`` either side of the threshold; the wall's
        colour goes from dark red at the threshold to pale pink deeper in the wall.
        """
        from ...core import TransferFunction

        t, w = self.threshold, max(0.15 * self.spread, 1e-3)
        sign = self.sign  # direction from the lumen into the wall
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
        return replace(self, value_range=(lo, hi))

    def with_threshold(self, threshold: float) -> LumenEstimate:
        """The same estimate with another wall threshold (data units); the grown range follows it."""
        t = float(threshold)
        lo, hi = self.value_range
        return replace(self, threshold=t, value_range=(lo, t) if self.kind == "air" else (t, hi))

    def describe(self, units: str = "") -> str:
        """One line for the user: what was chosen, values in the data's precision (``core.value_text``; ``units``
        as ``core.values_of(volume)`` gives them)."""
        def v(x):
            return value_text(x, units)

        lo, hi = self.value_range
        line = (f"lumen: {self.kind} (the lumen is {'darker' if self.kind == 'air' else 'brighter'} than its wall), "
                f"values {v(lo)}..{v(hi)}, wall threshold {v(self.threshold)}")
        if self.lumen is not None and self.wall is not None:
            line += f" (lumen {v(self.lumen)}, wall {v(self.wall)})"
        if self.tag is not None:
            line += f", tagged fluid {v(self.tag)} counted as lumen"
        return line

    def to_dict(self) -> dict:
        """JSON-ready dict of every field."""
        d = asdict(self)
        d["value_range"] = list(self.value_range)
        return d

    @classmethod
    def from_dict(cls, d: dict) -> LumenEstimate:
        known = set(cls.__dataclass_fields__)
        extra = set(d) - known
        if extra:
            raise ValueError(f"unknown LumenEstimate fields {sorted(extra)}; valid: {sorted(known)}")
        d = dict(d)
        d["value_range"] = tuple(float(v) for v in d["value_range"])
        return cls(**d)


def _ball(volume, zyx, radius: float) -> np.ndarray:
    sp = np.asarray(volume.spacing, float)
    r = np.ceil(radius / sp).astype(int)
    lo = np.maximum(np.asarray(zyx) - r, 0)
    hi = np.minimum(np.asarray(zyx) + r + 1, volume.shape)
    box = volume.data[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]]
    grids = np.ogrid[tuple(slice(int(a), int(b)) for a, b in zip(lo, hi, strict=True))]
    d2 = sum(((g - c) * s) ** 2 for g, c, s in zip(grids, zyx, sp, strict=True))
    return np.asarray(box[d2 <= radius * radius], np.float64)


def lumen_class(volume, zyx) -> tuple[float, float]:
    """``(value, noise)`` of the lumen round voxel ``zyx``: the median and the width / 1.349 of the densest half
    of the values in the ball two voxels (the largest spacing) in radius (at least a thousandth of the
    value's magnitude, for noise-free data)."""
    vals = np.sort(_ball(volume, zyx, 2.0 * float(max(volume.spacing))))
    half = vals.size // 2 + 1
    widths = vals[half - 1:] - vals[:vals.size - half + 1]
    k = int(np.argmin(widths))
    med = float(np.median(vals[k:k + half]))
    return med, max(float(widths[k]) / 1.349, 1e-3 * max(abs(med), 1.0))


def _spread_inside(volume, rays):
    """``(value, spread)`` of the voxels the rays crossed inside the lumen (the median, and the middle half's
    width / 1.349), or None when they are fewer than :data:`SETTLE_VOXELS`: the lumen's own variation at the
    vessel's scale (layered or mixed contrast), which the handful of voxels round the point does not show."""
    if len(rays.inside) < SETTLE_VOXELS:
        return None
    vals = np.asarray(volume.data[tuple(rays.inside.T)], np.float64)
    q1, med, q3 = np.quantile(vals, [0.25, 0.5, 0.75])
    return float(med), float(q3 - q1) / 1.349


def probe_lumen(volume, zyx, kind: str = "auto"):
    """:func:`estimate_lumen` and the :class:`~volumen.endoscopy._rays.RayProbe` it was made from.

    The estimate is made from the point's own class (:func:`lumen_class`), then again (up to :data:`SETTLE`
    times) from the lumen's value and spread over the voxels the rays crossed inside it, while that spread
    grows, by at most :data:`SETTLE_GROWTH` a step (more is the rays escaping into another class); the last
    estimate whose lumen and wall stand apart is kept, so a point in a layered lumen is neither refused nor
    given a wall read off the lumen's own darker layers. A point refused so whose rays meet one class in
    most directions (a pocket of unopacified blood in a contrast lumen) is estimated again from that class,
    and kept when its own value lies in that lumen's range."""
    if kind not in LUMEN_KINDS:
        raise ValueError(f"lumen kind must be one of {', '.join(LUMEN_KINDS)}; got {kind!r}")
    z, y, x = (int(v) for v in zyx)
    own, noise = lumen_class(volume, (z, y, x))
    try:
        return _settled(volume, (z, y, x), own, noise, kind)
    except ValueError as exc:
        found = _from_surroundings(volume, (z, y, x), own, noise, kind)
        if found is None:
            raise exc from None
        return found


def _settled(volume, zyx, lumen: float, noise: float, kind: str):
    """``(LumenEstimate, RayProbe)`` settled on the lumen's spread (see :func:`probe_lumen`); the first
    refusal's ValueError when none stands."""
    kept, first_error = None, None
    for _ in range(SETTLE):
        try:
            kept = _probe(volume, zyx, lumen, noise, kind)
        except ValueError as exc:
            first_error = first_error or exc
            break
        wider = _spread_inside(volume, kept[1])
        if wider is None or not noise * 1.1 < wider[1] <= SETTLE_GROWTH * noise:
            break
        lumen, noise = wider
    if kept is None:
        raise first_error
    return kept


def _from_surroundings(volume, zyx, own: float, noise: float, kind: str):
    """The estimate of the class that rays from ``zyx`` meet in more than :data:`POCKET` of the directions, from
    the voxel a voxel past where the median such ray met it; None unless ``own`` (the point's value) lies in
    that lumen's range."""
    from ._rays import cast_rays

    rays = cast_rays(volume, zyx, own, DEPARTURE * noise, REACH[0])
    for sign in (1, -1):
        meets = rays.hit & (rays.sign == sign)
        if meets.sum() <= POCKET * len(rays.hit):
            continue
        k = np.flatnonzero(meets)[np.argsort(rays.met[meets])[meets.sum() // 2]]
        step = rays.distance[k] + float(max(volume.spacing))
        point = volume.index_to_world(np.asarray(zyx, float)[::-1]) + step * rays.directions[k]
        there = tuple(int(v) for v in np.rint(volume.world_to_index(point)[::-1]))
        if not all(0 <= v < n for v, n in zip(there, volume.shape, strict=True)):
            continue
        try:
            est, found = _settled(volume, there, *lumen_class(volume, there), kind)
        except ValueError:
            continue
        lo, hi = est.value_range
        if lo <= own <= hi:
            return est, found
    return None


def _probe(volume, zyx, lumen: float, noise: float, kind: str):
    """The estimate from rays cast with the lumen's ``value`` and ``noise``: ``(LumenEstimate, RayProbe)``."""
    from ._rays import cast_rays

    for reach in REACH:
        rays = cast_rays(volume, zyx, lumen, DEPARTURE * noise, reach)
        if rays.hit.any():
            break
    else:
        raise ValueError(f"no wall within {REACH[-1]:g} mm of it: the data stays within "
                         f"{value_text(DEPARTURE * noise, **values_of(volume))} of its value "
                         f"{value_text(lumen, **values_of(volume))} in every direction")
    if kind == "auto":
        kind = "air" if np.sum(rays.sign > 0) >= np.sum(rays.sign < 0) else "contrast"
    sign = 1 if kind == "air" else -1
    met = rays.met[(rays.sign == sign) & np.isfinite(rays.met)]
    if met.size == 0:
        raise ValueError(f"no {'brighter' if sign > 0 else 'darker'} wall round it within {REACH[-1]:g} mm "
                         f"(forced --lumen {kind})")
    wall = float(np.quantile(met, WALL_QUANTILE if sign > 0 else 1.0 - WALL_QUANTILE))
    if abs(wall - lumen) < SEPARATION * noise:
        vals = values_of(volume)
        raise ValueError(f"its values ({value_text(lumen, **vals)} +- {value_text(noise, **vals)}) do not stand "
                         f"apart from those round it ({value_text(wall, **vals)}): it is tissue, not a lumen")
    t = 0.5 * (lumen + wall)
    lo, hi = volume.value_range()
    rng = (float(min(lo, lumen)), t) if kind == "air" else (t, float(max(hi, lumen)))
    est = LumenEstimate(kind=kind, value_range=rng, threshold=t, spread=abs(wall - lumen), lumen=lumen, wall=wall,
                        noise=noise)
    return est, rays


def estimate_lumen(volume, zyx, kind: str = "auto") -> LumenEstimate:
    """Polarity, value range and wall threshold of the lumen around voxel ``zyx``.

    Parameters
    ----------
    volume : Volume
    zyx : (3,) int
        A voxel inside the lumen, ``(z, y, x)``.
    kind : {"auto", "air", "contrast"}
        ``auto`` decides from the data round the voxel; the others force the polarity
        (the threshold and range still come from the data).

    Returns
    -------
    LumenEstimate

    Raises
    ------
    ValueError
        When no wall is met within 100 mm, or none of the forced polarity, or the wall's values do not
        stand apart from the lumen's (the point is in no lumen).
    """
    return probe_lumen(volume, zyx, kind)[0]
