"""Sort-last compositing of partial pictures: the associative "over" (composite), max (MIP), min (MinIP).

A :class:`Partial` is what one brick (or a run of consecutive bricks) drew:
premultiplied RGBA, depth, and the projected value (projection modes). The
operators are associative, so partials may be combined in any grouping as long
as their front-to-back order is kept (a tree of workers, or one by one):

- composite: ``front + (1 - front.alpha) * back``; depth: the nearest;
- mip / minip: per pixel the partial with the larger / smaller value (ties:
  the front one, as the ray caster keeps the first extreme it meets).

Drawn one after the other, front to back, composite partials carry the
opacity in front into the next one (``volumen.render.raycast.render_part``):
such a partial's colour is already seen through the opacity in front and its
alpha is the opacity accumulated up to its back, so :func:`add_carried` adds
the colours and keeps the larger alpha (the back one wherever it drew).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Partial", "combine", "add_carried", "empty_partial", "MODES"]

MODES = ("composite", "mip", "minip")


@dataclass
class Partial:
    """rgba (H, W, 4) float32 premultiplied, depth (H, W) mm (inf: none), value (H, W) (NaN: none); ``rect``
    ``(y0, y1, x0, x1)`` pixels, where known: outside it the partial is empty."""

    rgba: np.ndarray
    depth: np.ndarray
    value: np.ndarray
    rect: tuple[int, int, int, int] | None = None

    @classmethod
    def of(cls, image, rect=None) -> Partial:
        h, w = image.depth.shape
        value = image.value if image.value is not None else np.full((h, w), np.nan, np.float32)
        return cls(image.rgba, image.depth, value, rect)


def empty_partial(w: int, h: int) -> Partial:
    return Partial(np.zeros((h, w, 4), np.float32), np.full((h, w), np.inf, np.float32),
                   np.full((h, w), np.nan, np.float32))


def _pick(front: Partial, back: Partial, take_back: np.ndarray) -> Partial:
    return Partial(np.where(take_back[..., None], back.rgba, front.rgba), np.where(take_back, back.depth, front.depth),
                   np.where(take_back, back.value, front.value))


def combine(front: Partial, back: Partial, mode: str) -> Partial:
    """``front`` composited over ``back`` with the mode's operator (see the module docstring)."""
    if mode == "composite":
        rgba = front.rgba + (1.0 - front.rgba[..., 3:4]) * back.rgba
        return Partial(rgba.astype(np.float32), np.minimum(front.depth, back.depth), front.value)
    if mode not in ("mip", "minip"):
        raise ValueError(f"sort-last compositing takes modes {list(MODES)}, got {mode!r}")
    fv, bv = front.value, back.value
    beats = bv > fv if mode == "mip" else bv < fv
    return _pick(front, back, ~np.isnan(bv) & (np.isnan(fv) | beats))


def add_carried(front: Partial, back: Partial) -> Partial:
    """``back`` drawn with ``front``'s opacity carried in, added to ``front`` in place, over ``back.rect``
    (composite; see the module docstring); returns ``front``."""
    y0, y1, x0, x1 = back.rect if back.rect is not None else (0, None, 0, None)
    f, b = front.rgba[y0:y1, x0:x1], back.rgba[y0:y1, x0:x1]
    alpha = np.maximum(f[..., 3], b[..., 3])
    f += b
    f[..., 3] = alpha
    depth = front.depth[y0:y1, x0:x1]
    np.minimum(depth, back.depth[y0:y1, x0:x1], out=depth)
    return front
