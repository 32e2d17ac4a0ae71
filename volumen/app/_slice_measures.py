"""Measurements on a slice view, without Qt: the measurement a drag makes, and what of each measurement a slice
shows.

A ruler runs from the press to the pointer; a rectangle or ellipse spans the box between them on the slice's plane
(:func:`view_plane`: the plane through the slice's voxel centres, ``u`` along the display's columns, ``v`` down its
rows), its statistics taken over the scan's voxels (:func:`volumen.measure.roi_stats`). A slice shows a measurement
whole where it lies within half a slice of it, and where it only crosses the slice, the cut: the point a ruler
passes through, the chord of a region.
"""

from __future__ import annotations

import numpy as np

from ..core import mm_text, value_text
from ..measure import Distance, Ellipse, Plane, Rectangle, Scan, roi_stats

__all__ = ["TOOLS", "view_plane", "make", "handles", "grab", "drag_to", "slice_part", "caption"]

#: the measurement tools of a slice view
TOOLS = ("ruler", "rectangle", "ellipse")
#: how many points outline an ellipse when it is drawn or cut
_ELLIPSE_POINTS = 72


def view_plane(g, index: int) -> Plane:
    """The plane of slice ``index`` of slice geometry ``g``: ``u`` along display columns, ``v`` down rows."""
    o = g.display_to_world(0.5, 0.5, index)
    return Plane(tuple(o), g.display_to_world(1.5, 0.5, index) - o, g.display_to_world(0.5, 1.5, index) - o)


def _box(plane: Plane, a, b) -> tuple[tuple[float, float], tuple[float, float]]:
    (sa, ta), (sb, tb) = plane.to_plane(np.array([a, b]))[0]
    return (min(sa, sb), min(ta, tb)), (max(sa, sb), max(ta, tb))


def make(tool: str, a, b, volume, plane: Plane | None = None, label: str = ""):
    """The measurement of ``tool`` dragged from world point ``a`` to ``b`` on ``plane`` (a region's) of
    ``volume``."""
    if tool == "ruler":
        return Distance(a, b, scan=Scan.of(volume), label=label)
    lo, hi = _box(plane, a, b)
    lo = tuple(np.minimum(lo, np.subtract(hi, 1e-3)))  # a click without a drag: a region a micrometre wide
    if tool == "rectangle":
        shape = Rectangle(lo, hi)
    else:
        shape = Ellipse(tuple((np.add(lo, hi)) / 2), tuple(np.maximum(np.subtract(hi, lo) / 2, 1e-3)))
    return roi_stats(volume, plane, shape, label=label)


def handles(m) -> np.ndarray:
    """The world points a measurement is dragged by: a ruler's ends, a region's box corners ``(2, 3)``."""
    if m.kind == "distance":
        return np.array([m.start, m.end])
    lo, hi = m.shape.bounds()
    return m.plane.to_world(np.array([lo, hi]))


def grab(m, which: int) -> tuple:
    """What a drag of handle ``which`` (0 or 1) of ``m`` remakes: ``(tool, the other handle, which stays put,
    plane, label, which)`` (:func:`drag_to`)."""
    tool = "ruler" if m.kind == "distance" else m.shape.kind
    return tool, handles(m)[1 - which], getattr(m, "plane", None), m.label, which


def drag_to(recipe: tuple, world, volume):
    """The measurement of a drag (:func:`grab`'s recipe, or a new one's ``(tool, start, plane, "", 1)``) with the
    dragged handle at ``world`` (a region's kept on its plane)."""
    tool, fixed, plane, label, which = recipe
    if tool != "ruler":
        world = plane.to_world(plane.to_plane(world)[0])
    a, b = (world, fixed) if which == 0 else (fixed, world)
    return make(tool, a, b, volume, plane, label)


def outline(m) -> np.ndarray:
    """A measurement's outline in world mm: a ruler's two ends; a region's closed outline."""
    if m.kind == "distance":
        return np.array([m.start, m.end])
    if m.shape.kind == "ellipse":
        a = np.linspace(0, 2 * np.pi, _ELLIPSE_POINTS + 1)
        (cs, ct), (rs, rt) = m.shape.center, m.shape.radii
        st = np.stack([cs + rs * np.cos(a), ct + rt * np.sin(a)], -1)
    else:
        st = np.vstack([m.shape.outline(), m.shape.outline()[:1]])
    return m.plane.to_world(st)


def slice_part(g, index: int, m) -> tuple[str, np.ndarray] | None:
    """What slice ``index`` of geometry ``g`` shows of ``m``: ``("whole", points)`` where it lies within half a
    slice, ``("cut", points)`` where it crosses the slice (the crossing points), None where it misses it."""
    pts = outline(m)
    d = g.distance_to_slice(pts, index) * np.sign(g.volume.world_to_index(pts)[:, g.normal_axis] - index)
    if np.all(np.abs(d) <= 0.5):
        return "whole", pts
    crossings = []
    for k in range(len(pts) - 1):
        d0, d1 = d[k], d[k + 1]
        if d0 == 0.0:
            crossings.append(pts[k])
        elif d0 * d1 < 0:
            crossings.append(pts[k] + (pts[k + 1] - pts[k]) * d0 / (d0 - d1))
    if m.kind != "distance" and d[-1] == 0.0:
        crossings.append(pts[-1])
    return ("cut", np.array(crossings)) if crossings else None


def caption(m) -> str:
    """The value drawn beside a measurement: a ruler's length, a region's mean, SD and area."""
    if m.kind == "distance":
        return f"{mm_text(m.mm)} mm"
    unit = f" {m.units}" if m.units else ""
    return (f"mean {value_text(m.mean, m.units)}{unit}  SD {value_text(m.sd, m.units)}  "
            f"{m.area_mm2:.1f} mm\u00b2")
