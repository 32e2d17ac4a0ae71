"""The point of the 3-D picture under a click: the first visible surface along the pixel's ray.

"Visible" is the ray caster's own: where the accumulated opacity of the scene's transfer function first reaches
its depth threshold (``Image.depth``, docs/design.md section 2), with the scene's clipping, crop and mode. The
ray is cast alone: a one-pixel picture from the same eye along the clicked point's ray (perspective), or from the
point of the image plane under it (orthographic), on the device asked (the CPU by default), without the scene's
jitter: a jittered ray's depth moves by up to a step, and where it grazes a thin or faint structure it can pass
through or stop there (a pixel grazing the head phantom's cheek: 504 mm in the whole picture, 525 mm cast alone),
so a picked point would not repeat; unjittered, a pick is the picture's unjittered depth at that pixel. Every front end
picks through here, the browser page through the server (``region.json``'s neighbour ``pick.json``), so a point
picked in one viewer is the point picked in another.
"""

from __future__ import annotations

import numpy as np

__all__ = ["pixel_ray", "pick"]

#: the field of view (degrees) / half height (mm) of the one-pixel picture: far below a voxel at any distance
_NARROW_FOV = 1e-3
_NARROW_SCALE = 1e-3


def pixel_ray(camera, size: tuple[int, int], x: float, y: float) -> tuple[np.ndarray, np.ndarray]:
    """``(origin, unit direction)`` in world mm of the ray through the picture's point ``(x, y)`` (continuous
    pixels, ``(0, 0)`` the top-left corner): ``Camera.pixel_ray``."""
    return camera.pixel_ray(size, x, y)


def pick(scene, camera, size: tuple[int, int], x: float, y: float, device: str = "cpu") -> np.ndarray | None:
    """The world point (mm, RAS+) of the first visible surface under the picture's point ``(x, y)`` of ``scene``
    seen by ``camera`` at ``size``; None where the ray meets nothing visible."""
    from dataclasses import replace

    from volumen.render import render

    origin, direction = pixel_ray(camera, size, x, y)
    _, up, _ = camera.basis()
    up = up if abs(np.dot(up, direction)) < 0.99 else camera.basis()[0]
    narrow = camera.with_(position=tuple(origin), target=tuple(origin + direction * max(camera.distance, 1.0)),
                          up=tuple(up), fov=_NARROW_FOV, parallel_scale=_NARROW_SCALE)
    steady = scene.with_(sampling=replace(scene.sampling, jitter=False))
    depth = float(render(steady, narrow, (1, 1), device=device).depth[0, 0])
    return origin + depth * direction if np.isfinite(depth) else None
