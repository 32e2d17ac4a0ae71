"""Mouse gestures of a 3D view as camera and light arithmetic (plain numpy): the desktop application
and the notebook widget turn the same drag into the same camera.

Pixel offsets are ``(dx, dy)`` with x to the right and y DOWN the screen, as
mouse events give them.

* :func:`orbit`: the eye turns about the target: ``dx`` about the camera's up
  axis, ``dy`` about its right axis, :data:`DEGREES_PER_PIXEL` per pixel; the
  distance to the target is kept. Dragging to the right turns the volume to
  the right (the eye moves to the left).
* :func:`pan`: eye and target slide in the view plane so the point under the
  mouse at the target's depth follows the mouse.
* :func:`zoom`: the eye moves toward the target (perspective) or the parallel
  scale shrinks (orthographic) by ``factor``; :func:`drag_zoom` (a vertical drag, up = closer,
  ``exp(-dy * ZOOM_PER_PIXEL)``) and :func:`wheel_zoom` (``WHEEL_ZOOM`` per notch away from the user).
* :func:`move_light`, :func:`aim_light`: a selected light follows the mouse in
  the view plane at its own depth, or turns its spot axis.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ._camera import Camera
from ._lighting import Light

__all__ = ["DEGREES_PER_PIXEL", "ZOOM_PER_PIXEL", "WHEEL_ZOOM", "orbit", "pan", "zoom", "drag_zoom", "wheel_zoom",
           "mm_per_pixel", "move_light", "aim_light", "light_at_camera", "rotate"]

#: orbit and aim speed: degrees of rotation per pixel of mouse motion
DEGREES_PER_PIXEL = 0.5
#: drag zoom speed: the magnification is ``exp(-dy * ZOOM_PER_PIXEL)`` for a drag of ``dy`` pixels
ZOOM_PER_PIXEL = 0.01
#: magnification of one wheel notch
WHEEL_ZOOM = 1.1


def rotate(v, axis, degrees: float) -> np.ndarray:
    """``v`` turned by ``degrees`` about the unit ``axis`` (right-hand rule, Rodrigues)."""
    v = np.asarray(v, float)
    k = np.asarray(axis, float)
    k = k / np.linalg.norm(k)
    a = np.radians(degrees)
    return v * np.cos(a) + np.cross(k, v) * np.sin(a) + k * np.dot(k, v) * (1 - np.cos(a))


def orbit(camera: Camera, dx: float, dy: float) -> Camera:
    """The camera after a drag of ``(dx, dy)`` pixels: ``-dx * DEGREES_PER_PIXEL`` about its up axis, then
    ``-dy * DEGREES_PER_PIXEL`` about its right axis, both through the target."""
    r, u, _f = camera.basis()
    target = np.asarray(camera.target, float)
    back = np.asarray(camera.position, float) - target
    yaw, pitch = -dx * DEGREES_PER_PIXEL, -dy * DEGREES_PER_PIXEL
    back = rotate(back, u, yaw)
    r2 = rotate(r, u, yaw)
    back = rotate(back, r2, pitch)
    up = rotate(u, r2, pitch)
    return camera.with_(position=tuple(target + back), up=tuple(up))


def mm_per_pixel(camera: Camera, size: tuple[int, int], depth: float | None = None) -> float:
    """Size (mm) of one pixel at ``depth`` mm from the eye (default: the target's distance)."""
    _, h = size
    if camera.projection == "orthographic":
        return 2.0 * camera.parallel_scale / h
    d = camera.distance if depth is None else float(depth)
    return 2.0 * d * np.tan(np.radians(camera.fov) / 2) / h


def pan(camera: Camera, dx: float, dy: float, size: tuple[int, int]) -> Camera:
    """Slide eye and target so the scene follows a drag of ``(dx, dy)`` pixels."""
    r, u, _ = camera.basis()
    s = mm_per_pixel(camera, size)
    shift = (-dx * r + dy * u) * s
    return camera.with_(position=tuple(np.add(camera.position, shift)), target=tuple(np.add(camera.target, shift)))


def zoom(camera: Camera, factor: float) -> Camera:
    """Magnify by ``factor`` (> 1 closer): the eye-target distance, or the parallel scale, divided by it."""
    if not factor > 0:
        raise ValueError(f"zoom factor must be > 0, got {factor}")
    if camera.projection == "orthographic":
        return camera.with_(parallel_scale=camera.parallel_scale / factor)
    t = np.asarray(camera.target, float)
    back = (np.asarray(camera.position, float) - t) / factor
    if np.linalg.norm(back) < 1e-3:
        return camera
    return camera.with_(position=tuple(t + back))


def drag_zoom(camera: Camera, dy: float) -> Camera:
    """The camera after a vertical drag of ``dy`` pixels (down positive): up magnifies."""
    return zoom(camera, float(np.exp(-dy * ZOOM_PER_PIXEL)))


def wheel_zoom(camera: Camera, notches: float) -> Camera:
    """The camera after ``notches`` wheel notches (positive: away from the user, magnifies)."""
    return zoom(camera, WHEEL_ZOOM ** float(notches))


def light_at_camera(camera: Camera, *, exponent: float = 10.0, intensity: float = 1.0) -> Light:
    """A spot light at the eye, shining where the camera looks (key J)."""
    _, _, f = camera.basis()
    return Light(position=tuple(camera.position), direction=tuple(f), exponent=exponent, intensity=intensity,
                 kind="spot")


def move_light(light: Light, camera: Camera, dx: float, dy: float, size: tuple[int, int]) -> Light:
    """A world light moved in the view plane by a drag of ``(dx, dy)`` pixels at its own depth.

    Lights attached to the camera move by the same offset along the camera's right and up axes.
    """
    r, u, f = camera.basis()
    if light.attach == "camera":
        depth = max(float(light.position[2]), 1.0)
        s = mm_per_pixel(camera, size, depth)
        return replace(light, position=tuple(np.add(light.position, (dx * s, -dy * s, 0.0))))
    p = np.asarray(light.position, float)
    depth = float(np.dot(p - np.asarray(camera.position, float), f))
    s = mm_per_pixel(camera, size, max(depth, 1.0))
    return replace(light, position=tuple(p + (dx * r - dy * u) * s))


def aim_light(light: Light, camera: Camera, dx: float, dy: float) -> Light:
    """A light whose spot axis turned by a drag: ``dx`` about the camera's up, ``dy`` about its right axis."""
    if light.attach == "camera":
        r, u = np.array([1.0, 0, 0]), np.array([0, 1.0, 0])
    else:
        r, u, _ = camera.basis()
    d = rotate(light.direction, u, dx * DEGREES_PER_PIXEL)
    d = rotate(d, r, dy * DEGREES_PER_PIXEL)
    return replace(light, direction=tuple(d))
