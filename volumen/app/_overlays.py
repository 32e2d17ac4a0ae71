"""What the 3D view draws over the picture, as 2-D screen geometry (plain numpy, no Qt).

Everything goes through :meth:`volumen.core.Camera.project`, so the overlay
lines up with the rendered picture: lights as cones pointing where they shine,
the crosshair's three axes across the volume, a centerline as a polyline.
Coordinates are ``(column, row)`` pixels of a picture of ``size``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core import Camera, Light

__all__ = ["Cone", "light_cone", "pick_light", "project_polyline", "crosshair_lines"]


@dataclass
class Cone:
    """A light drawn as a cone: ``apex`` where the light is, ``rim`` the base circle ahead of it.

    ``apex`` (2,) and ``rim`` (n, 2) in pixels; ``outline`` the convex polygon
    (n, 2) of apex and rim; ``visible`` False when the light is behind the eye.
    """

    apex: np.ndarray
    rim: np.ndarray
    outline: np.ndarray
    visible: bool


def _cross2(a, b) -> float:
    return float(a[0] * b[1] - a[1] * b[0])


def _hull(points: np.ndarray) -> np.ndarray:
    """Convex hull (monotone chain) of (n, 2) points, counter-clockwise."""
    pts = sorted(map(tuple, np.round(points, 6)))
    if len(pts) <= 2:
        return np.array(pts)

    def half(seq):
        out: list = []
        for p in seq:
            while len(out) >= 2 and _cross2(np.subtract(out[-1], out[-2]), np.subtract(p, out[-2])) <= 0:
                out.pop()
            out.append(p)
        return out

    lower, upper = half(pts), half(pts[::-1])
    return np.array(lower[:-1] + upper[:-1])


def light_cone(light: Light, camera: Camera, size: tuple[int, int], length: float, *, scale: float = 1.0,
               segments: int = 16) -> Cone:
    """The cone of ``light`` (``length`` mm long, opening 25 degrees, times ``scale``) on the screen."""
    pos, d = light.in_world(camera)
    length = length * scale
    radius = length * np.tan(np.radians(25.0))
    a = np.cross(d, [1.0, 0, 0] if abs(d[0]) < 0.9 else [0, 1.0, 0])
    a /= np.linalg.norm(a)
    b = np.cross(d, a)
    t = np.linspace(0, 2 * np.pi, segments, endpoint=False)
    rim3 = pos + d * length + radius * (np.cos(t)[:, None] * a + np.sin(t)[:, None] * b)
    pts, depth = camera.project(np.vstack([pos[None], rim3]), size)
    visible = bool(np.all(depth > 0) and np.all(np.isfinite(pts)))
    if camera.projection == "perspective":
        _, _, f = camera.basis()
        ahead = (np.vstack([pos[None], rim3]) - np.asarray(camera.position)) @ f
        visible = visible and bool(np.all(ahead > 1e-3))
    apex, rim = pts[0], pts[1:]
    outline = _hull(pts) if visible else np.zeros((0, 2))
    return Cone(apex=apex, rim=rim, outline=outline, visible=visible)


def pick_light(lights, camera: Camera, size: tuple[int, int], length: float, xy, radius: float = 10.0):
    """Index of the light whose cone is under the pixel ``xy`` (or within ``radius`` px of its apex), else None.

    Lights attached to the camera and head lights are at the eye and cannot be picked.
    """
    best, best_d = None, np.inf
    p = np.asarray(xy, float)
    for n, light in enumerate(lights):
        if light.kind == "headlight" or light.attach == "camera":
            continue
        cone = light_cone(light, camera, size, length)
        if not cone.visible:
            continue
        d = float(np.linalg.norm(cone.apex - p))
        if _inside(cone.outline, p):
            d = min(d, radius * 0.5)
        if d <= radius and d < best_d:
            best, best_d = n, d
    return best


def _inside(poly: np.ndarray, p: np.ndarray) -> bool:
    if len(poly) < 3:
        return False
    e = np.roll(poly, -1, axis=0) - poly
    c = e[:, 0] * (p[1] - poly[:, 1]) - e[:, 1] * (p[0] - poly[:, 0])
    return bool(np.all(c >= 0) or np.all(c <= 0))


def project_polyline(points, camera: Camera, size: tuple[int, int]) -> list[np.ndarray]:
    """World polyline (n, 3) -> list of screen runs (m, 2), split where points fall behind the eye."""
    pts, depth = camera.project(np.asarray(points, float), size)
    _, _, f = camera.basis()
    ahead = (np.asarray(points, float) - np.asarray(camera.position)) @ f > 1e-3
    ok = ahead & np.all(np.isfinite(pts), axis=1)
    runs, cur = [], []
    for q, good in zip(pts, ok, strict=True):
        if good:
            cur.append(q)
        elif cur:
            runs.append(np.array(cur))
            cur = []
    if cur:
        runs.append(np.array(cur))
    return [r for r in runs if len(r) >= 2]


def crosshair_lines(volume, point, camera: Camera, size: tuple[int, int]) -> list[tuple[int, np.ndarray]]:
    """The crosshair's three axis lines across the volume's box: ``[(axis, (2, 2) pixels), ...]``, axis 0=x 1=y 2=z."""
    lo, hi = volume.bounds()
    out = []
    for ax in range(3):
        a, b = np.array(point, float), np.array(point, float)
        a[ax], b[ax] = lo[ax], hi[ax]
        runs = project_polyline(np.linspace(a, b, 8), camera, size)
        for r in runs:
            out.append((ax, r[[0, -1]]))
    return out
