"""OpenGL matrices for a :class:`~volumen.core.Camera`, matching ``Camera.project`` pixel for pixel.

``Camera.project`` puts a point at column ``w/2 + sx h/2`` and row
``h/2 - sy h/2`` with ``sx, sy`` its coordinates over the half height of the
view (perspective: divided by the view depth and ``tan(fov/2)``). The
matrices here give the same normalized device coordinates with
``x_ndc = sx h / w`` and ``y_ndc = sy``; OpenGL's window row 0 is the BOTTOM,
which the read-back flips.
"""

from __future__ import annotations

import numpy as np

__all__ = ["view_matrix", "projection_matrix", "view_depth_range", "as_uniform"]


def view_matrix(camera) -> np.ndarray:
    """(4, 4) float64 world RAS+ mm -> eye space (x right, y up, looking down -z), row-major."""
    r, u, f = camera.basis()
    m = np.eye(4)
    m[0, :3], m[1, :3], m[2, :3] = r, u, -f
    m[:3, 3] = -m[:3, :3] @ np.asarray(camera.position)
    return m


def projection_matrix(camera, size, near: float, far: float) -> np.ndarray:
    """(4, 4) float64 eye space -> clip space for an image of ``size = (width, height)``.

    ``near`` and ``far`` (mm, > 0 for perspective) bound the view depth
    ``dot(p - position, forward)`` OpenGL keeps.
    """
    w, h = size
    aspect = w / h
    n, f = float(near), float(far)
    p = np.zeros((4, 4))
    if camera.projection == "orthographic":
        s = camera.parallel_scale
        p[0, 0] = 1.0 / (s * aspect)
        p[1, 1] = 1.0 / s
        p[2, 2] = -2.0 / (f - n)
        p[2, 3] = -(f + n) / (f - n)
        p[3, 3] = 1.0
    else:
        t = np.tan(np.radians(camera.fov) / 2)
        p[0, 0] = 1.0 / (t * aspect)
        p[1, 1] = 1.0 / t
        p[2, 2] = -(f + n) / (f - n)
        p[2, 3] = -2.0 * f * n / (f - n)
        p[3, 2] = -1.0
    return p


def view_depth_range(camera, points) -> tuple[float, float]:
    """``(min, max)`` of the view depth ``dot(p - position, forward)`` (mm) over ``points`` (N, 3) world mm."""
    _, _, f = camera.basis()
    z = (np.asarray(points, float) - np.asarray(camera.position)) @ f
    return float(z.min()), float(z.max())


def as_uniform(m: np.ndarray) -> bytes:
    """A row-major (4, 4) or (3, 3) matrix as the column-major float32 bytes a GLSL ``mat`` uniform takes."""
    return np.ascontiguousarray(np.asarray(m, np.float32).T).tobytes()
