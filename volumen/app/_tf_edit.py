"""Editing a transfer function's control points (plain Python, no Qt).

The editor widget turns mouse gestures into these calls; each returns a new
:class:`~volumen.core.TransferFunction` (they are frozen), keeping the points
ordered: a dragged point stays between its neighbours.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..core import TransferFunction

__all__ = ["move_opacity_point", "add_opacity_point", "remove_opacity_point", "move_color_stop",
           "set_color_stop", "add_color_stop", "remove_color_stop", "log_histogram"]


def _clamp_between(points, index: int, value: float) -> float:
    lo = points[index - 1][0] if index > 0 else -np.inf
    hi = points[index + 1][0] if index < len(points) - 1 else np.inf
    return float(min(max(value, lo), hi))


def move_opacity_point(tf: TransferFunction, index: int, value: float, alpha: float) -> TransferFunction:
    """Move opacity point ``index`` to ``(value, alpha)`` (value kept between its neighbours, alpha in [0, 1])."""
    pts = [list(p) for p in tf.opacity]
    pts[index] = [_clamp_between(tf.opacity, index, value), float(np.clip(alpha, 0.0, 1.0))]
    return replace(tf, opacity=tuple(tuple(p) for p in pts), name=tf.name.split(" (edited)")[0] + " (edited)")


def _inserted(points, row: tuple) -> tuple[tuple, int]:
    """``points`` (sorted by value) with ``row`` inserted in order, and the row's index."""
    pts = list(points)
    i = int(np.searchsorted([p[0] for p in pts], row[0]))
    pts.insert(i, row)
    return tuple(pts), i


def _removed(points, index: int) -> tuple | None:
    """``points`` without row ``index``; None when only two rows are left (they always stay)."""
    if len(points) <= 2:
        return None
    return tuple(p for n, p in enumerate(points) if n != index)


def add_opacity_point(tf: TransferFunction, value: float, alpha: float) -> tuple[TransferFunction, int]:
    """Insert an opacity point; returns the new function and the point's index."""
    pts, i = _inserted(tf.opacity, (float(value), float(np.clip(alpha, 0.0, 1.0))))
    return replace(tf, opacity=pts), i


def remove_opacity_point(tf: TransferFunction, index: int) -> TransferFunction:
    """Remove an opacity point (the last two points always stay)."""
    pts = _removed(tf.opacity, index)
    return tf if pts is None else replace(tf, opacity=pts)


def move_color_stop(tf: TransferFunction, index: int, value: float) -> TransferFunction:
    """Move colour stop ``index`` to data ``value`` (kept between its neighbours)."""
    pts = [list(p) for p in tf.color]
    pts[index][0] = _clamp_between(tf.color, index, value)
    return replace(tf, color=tuple(tuple(p) for p in pts))


def set_color_stop(tf: TransferFunction, index: int, rgb) -> TransferFunction:
    """Give colour stop ``index`` the linear RGB ``rgb`` (three floats in [0, 1])."""
    pts = [list(p) for p in tf.color]
    pts[index][1:] = [float(np.clip(c, 0.0, 1.0)) for c in rgb]
    return replace(tf, color=tuple(tuple(p) for p in pts))


def add_color_stop(tf: TransferFunction, value: float) -> tuple[TransferFunction, int]:
    """Insert a colour stop at ``value`` with the colour the function has there."""
    rgb = tf.evaluate([value])[0, :3]
    pts, i = _inserted(tf.color, (float(value), *(float(c) for c in rgb)))
    return replace(tf, color=pts), i


def remove_color_stop(tf: TransferFunction, index: int) -> TransferFunction:
    """Remove a colour stop (the last two stay)."""
    pts = _removed(tf.color, index)
    return tf if pts is None else replace(tf, color=pts)


def log_histogram(volume, bins: int = 256, value_range=None) -> tuple[np.ndarray, np.ndarray]:
    """``(heights (bins,) in [0, 1], edges (bins + 1,))``: ``log(1 + count)`` scaled to its maximum, over
    ``value_range`` (default: the data range)."""
    counts, edges = volume.histogram(bins=bins, range=value_range)
    h = np.log1p(counts.astype(float))
    m = h.max()
    return (h / m if m > 0 else h), edges
