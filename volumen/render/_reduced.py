"""Reduced viewport: render at a fraction of the size, then upscale (any device and technique, so beside ``_api``).

While the user drags the camera, the application renders at half the size
(the source found one half keeps the picture's quality while dragging) and
shows it upscaled; the full-size frame follows when the mouse stops. The
low-resolution picture keeps the camera's frustum: with ``Camera.project``
scaling both axes by the image height, output pixel centre ``c + 0.5`` maps to
``w'/2 + (c + 0.5 - w/2) h'/h`` in the small image (rows alike), which is what
:func:`upscale` samples. Colour is interpolated bilinearly (premultiplied, so
edges do not darken); depth takes the nearest sample (interpolating across a
silhouette would invent surfaces).
"""

from __future__ import annotations

import time

import numpy as np

from ..core import Image
from ._api import render

__all__ = ["render_reduced", "reduced_size", "upscale"]


def reduced_size(size, fraction: float) -> tuple[int, int]:
    """``(width, height)`` of the reduced viewport: each side times ``fraction`` (rounded, at least 1)."""
    if not 0.0 < float(fraction) <= 1.0:
        raise ValueError(f"fraction must be in (0, 1], got {fraction}")
    w, h = (int(s) for s in size)
    return max(1, int(round(w * fraction))), max(1, int(round(h * fraction)))


def _coords(n_out: int, half_out: float, half_in: float, scale: float, n_in: int):
    """Source indices (lower, upper), bilinear weight and nearest index of each output pixel on one axis."""
    x = half_in + (np.arange(n_out) + 0.5 - half_out) * scale - 0.5   # continuous source index
    x = np.clip(x, 0.0, n_in - 1)
    i0 = np.minimum(np.floor(x).astype(np.int64), n_in - 1)
    i1 = np.minimum(i0 + 1, n_in - 1)
    return i0, i1, x - i0, np.clip(np.rint(x).astype(np.int64), 0, n_in - 1)


def upscale(image, size):
    """The :class:`~volumen.core.Image` ``image`` resampled to ``size = (width, height)`` with the same frustum.

    ``rgba`` bilinear, ``depth`` (and ``value``) nearest; ``stats`` kept.
    """
    w, h = (int(s) for s in size)
    hs, ws = image.rgba.shape[:2]
    scale = hs / h
    x0, x1, fx, xn = _coords(w, w / 2, ws / 2, scale, ws)
    y0, y1, fy, yn = _coords(h, h / 2, hs / 2, scale, hs)
    src = image.rgba
    fx4 = fx[None, :, None].astype(np.float32)
    top = src[y0][:, x0] * (1 - fx4) + src[y0][:, x1] * fx4
    bot = src[y1][:, x0] * (1 - fx4) + src[y1][:, x1] * fx4
    fy4 = fy[:, None, None].astype(np.float32)
    rgba = top * (1 - fy4) + bot * fy4
    depth = image.depth[yn][:, xn]
    value = None if image.value is None else image.value[yn][:, xn]
    return Image(rgba=rgba, depth=depth, stats=dict(image.stats), value=value)


def render_reduced(scene, camera, size, fraction: float = 0.5, **how):
    """Render through ``volumen.render.render(scene, camera, ..., **how)`` at ``fraction`` of ``size``, upscaled.

    Parameters
    ----------
    scene : Scene
    camera : Camera
    size : (width, height), pixels of the returned picture
    fraction : float in (0, 1]
        Side ratio of the rendered viewport (0.5: a quarter of the pixels).
    **how
        ``device``, ``technique`` and the technique's options, as in ``volumen.render.render``.

    Returns
    -------
    Image
        Of ``size``; ``stats`` are the small render's plus ``reduced``:
        ``fraction``, ``render_size``, and ``timings["upscale"]`` (seconds).
    """
    small = reduced_size(size, fraction)
    img = render(scene, camera, small, **how)
    if small == tuple(int(s) for s in size):
        return img
    t = time.perf_counter()
    out = upscale(img, size)
    out.display = img.display
    out.stats["timings"] = dict(img.stats.get("timings", {}), upscale=time.perf_counter() - t)
    out.stats["reduced"] = {"fraction": float(fraction), "render_size": small}
    return out
