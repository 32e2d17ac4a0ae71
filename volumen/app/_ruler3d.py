"""The 3-D view's ruler: two clicks on the picture pick two points of the first visible surface under them
(``volumen.measure.pick``: the ray caster's first hit for the current transfer function) and make a ruler
between them; every ruler is drawn over the rendering with its length beside it (and on the slice views that
cut it, as any ruler)."""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QPointF, Qt
from PySide6.QtGui import QColor, QPen

from ..measure import distance, pick
from ._slice_measures import caption

__all__ = ["Ruler3D"]

_COLOUR = QColor(255, 235, 60)


class Ruler3D:
    """The 3-D ruler tool of a :class:`~volumen.app._view3d.View3D`.

    Attributes
    ----------
    active : bool
        Whether a left click picks (instead of orbiting).
    pending : (3,) float or None
        The first point picked, world mm, until the second.
    captions : list of (str, (x, y))
        The lengths drawn at the last paint and where (widget px).
    """

    def __init__(self, view):
        self.view = view
        self.active = False
        self.pending: np.ndarray | None = None
        self.captions: list[tuple[str, tuple[float, float]]] = []

    def set_active(self, on: bool) -> None:
        self.active = bool(on)
        self.pending = None
        self.view.update()

    def press(self, x: float, y: float) -> bool:
        """Pick the point under ``(x, y)``; the second pick makes the ruler. True when the click was taken (a
        click on nothing visible is taken too, and picks nothing)."""
        if not self.active:
            return False
        st = self.view.state
        # the ray of the picture's pixel under the pointer: its centre
        hit = pick(st.scene, st.camera, self.view.view_size, np.floor(x) + 0.5, np.floor(y) + 0.5)
        if hit is None:
            self.view.status_text = "nothing visible there to measure from"
        elif self.pending is None:
            self.pending = hit
            self.view.status_text = "3-D ruler: click its other end"
        else:
            st.put_measurement(None, distance(self.pending, hit, volume=st.volume))
            self.pending, self.view.status_text = None, ""
        self.view.update()
        return True

    def paint(self, p, cam, size) -> None:
        """Draw the rulers (and the pending point) over the picture."""
        self.captions = []
        rulers = [m for m in self.view.state.measurements if m.kind == "distance"]
        p.setPen(QPen(_COLOUR, 2))
        for m in rulers:
            (a, b), depth = cam.project(np.array([m.start, m.end]), size)
            if not np.all(depth > 0):
                continue  # behind the eye
            p.drawLine(QPointF(*a), QPointF(*b))
            for q in (a, b):
                p.drawEllipse(QPointF(*q), 3.0, 3.0)
            x, y = max(a[0], b[0]) + 6, min(a[1], b[1]) - 4
            text = caption(m)
            p.drawText(QPointF(x, y), text)
            self.captions.append((text, (float(x), float(y))))
        if self.pending is not None:
            (q,), _ = cam.project(self.pending[None], size)
            p.setBrush(Qt.NoBrush)
            p.drawEllipse(QPointF(*q), 5.0, 5.0)


