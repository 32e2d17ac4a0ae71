"""Measurements on a slice view, without Qt: the measurement a drag makes, and what of each measurement a slice
shows.

A ruler runs from the press to the pointer; an angle has its first arm dragged (first point to vertex) and its
second point placed by the next press; a point is where the press is; a free-hand polygon is the path the pointer
traces; a rectangle or ellipse spans the box between the press and the pointer on the slice's plane
(:func:`view_plane`: the plane through the slice's voxel centres, ``u`` along the display's columns, ``v`` down its
rows), its statistics taken over the scan's voxels (:func:`volumen.measure.roi_stats`). A slice shows a measurement
whole where it lies within half a slice of it, and where it only crosses the slice, the cut: the point a ruler
passes through, the chord of a region.
"""

from __future__ import annotations

import numpy as np

from ..core import mm_text, value_text
from ..measure import Angle, Distance, Ellipse, Plane, Point, Polygon, Rectangle, Scan, point_value, roi_stats

__all__ = ["TOOLS", "view_plane", "make", "handles", "grab", "drag_to", "slice_part", "caption"]

#: the measurement tools of a slice view
TOOLS = ("ruler", "angle", "point", "rectangle", "ellipse", "polygon")
#: the tools that make a region on the slice's plane
REGION_TOOLS = ("rectangle", "ellipse", "polygon")
#: the measurement kinds drawn on a slice view (the kind each tool makes)
SHOWN = ("distance", "angle", "point", "region")
#: how many points outline an ellipse when it is drawn or cut
_ELLIPSE_POINTS = 72


def view_plane(g, index: int) -> Plane:
    """The plane of slice ``index`` of slice geometry ``g``: ``u`` along display columns, ``v`` down rows."""
    o = g.display_to_world(0.5, 0.5, index)
    return Plane(tuple(o), g.display_to_world(1.5, 0.5, index) - o, g.display_to_world(0.5, 1.5, index) - o)


def _box(plane: Plane, a, b) -> tuple[tuple[float, float], tuple[float, float]]:
    (sa, ta), (sb, tb) = plane.to_plane(np.array([a, b]))[0]
    return (min(sa, sb), min(ta, tb)), (max(sa, sb), max(ta, tb))


def make(tool: str, points, volume, plane: Plane | None = None, label: str = ""):
    """The measurement of ``tool`` through world ``points`` (a ruler's ends, an angle's first point, vertex and
    second point, a point, a polygon's vertices, a region's opposite box corners on ``plane``) of ``volume``."""
    scan = Scan.of(volume)
    if tool == "ruler":
        return Distance(*points, scan=scan, label=label)
    if tool == "angle":
        return Angle(*points, scan=scan, label=label)
    if tool == "point":
        return Point(points[0], scan=scan, label=label)
    if tool == "polygon":
        return roi_stats(volume, plane, Polygon(plane.to_plane(np.asarray(points, float))[0]), label=label)
    lo, hi = _box(plane, *points)
    lo = tuple(np.minimum(lo, np.subtract(hi, 1e-3)))  # a click without a drag: a region a micrometre wide
    if tool == "rectangle":
        shape = Rectangle(lo, hi)
    else:
        shape = Ellipse(tuple((np.add(lo, hi)) / 2), tuple(np.maximum(np.subtract(hi, lo) / 2, 1e-3)))
    return roi_stats(volume, plane, shape, label=label)


def handles(m) -> np.ndarray:
    """The world points a measurement is dragged by ``(n, 3)``: its points, a polygon's vertices, a region's box
    corners."""
    if m.kind != "region" or m.shape.kind == "polygon":
        return np.array(m.points)
    lo, hi = m.shape.bounds()
    return m.plane.to_world(np.array([lo, hi]))


def _tool_of(m) -> str:
    return {"distance": "ruler", "angle": "angle", "point": "point"}.get(m.kind) or m.shape.kind


def grab(m, which: int) -> tuple:
    """What a drag of handle ``which`` of ``m`` remakes: ``(tool, its handles, plane, label, which)``
    (:func:`drag_to`)."""
    return _tool_of(m), handles(m), getattr(m, "plane", None), m.label, which


def drag_to(recipe: tuple, world, volume):
    """The measurement of a drag (:func:`grab`'s recipe, or a new one's ``(tool, points, plane, "", which)``) with
    the dragged handle at ``world`` (a region's kept on its plane)."""
    tool, points, plane, label, which = recipe
    if tool in REGION_TOOLS:
        world = plane.to_world(plane.to_plane(world)[0])
    points = [np.asarray(p, float) for p in points]
    points[which] = np.asarray(world, float)
    return make(tool, points, volume, plane, label)


def outline(m) -> np.ndarray:
    """A measurement's outline in world mm: a ruler's two ends, an angle's three points, a point; a region's closed
    outline."""
    if m.kind != "region":
        return np.array(m.points)
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
    if m.kind == "region" and d[-1] == 0.0:
        crossings.append(pts[-1])
    return ("cut", np.array(crossings)) if crossings else None


def caption(m, volume=None) -> str:
    """The value drawn beside a measurement: a ruler's length, an angle's degrees, a point's world coordinates and
    the scan's value there (of ``volume``), a region's mean, SD and area."""
    if m.kind == "distance":
        return f"{mm_text(m.mm)} mm"
    if m.kind == "angle":
        return f"{m.degrees:.1f}\u00b0"
    if m.kind == "point":
        at = " ".join(mm_text(c) for c in m.position) + " mm"
        found = None if volume is None else point_value(volume, m.position)
        return at if found is None else f"{at}  {value_text(*found)}{' ' + found[1] if found[1] else ''}"
    unit = f" {m.units}" if m.units else ""
    return (f"mean {value_text(m.mean, m.units)}{unit}  SD {value_text(m.sd, m.units)}  "
            f"{m.area_mm2:.1f} mm\u00b2")
