"""The endoscopy panel's profile: the lumen's diameter along the flight's path, and the numbers where the eye is.

:class:`ProfileView` draws a :class:`~volumen.analysis.Profile` (:func:`volumen.analysis.measure` of the lumen
the panel computed, along its centerline) as the equivalent diameter against the distance along the path, the
minimum and maximum diameters as a band round it (the plot's top the largest, its width the path's length,
both written on it), the stenosis and the maximum marked, and a vertical line at
the eye's distance along the path (its projection onto the centerline). Under the plot a line gives the
current cross-section's numbers (:meth:`ProfileView.numbers`): distance, area, equivalent, minimum and maximum
diameter and the inscribed sphere's radius, in mm to 0.1.
"""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QPointF, Qt
from PySide6.QtGui import QColor, QPainter, QPen, QPolygonF
from PySide6.QtWidgets import QLabel, QVBoxLayout, QWidget

__all__ = ["ProfileView", "section_text"]

#: the plot's height (pixels) and its margin round the curves
HEIGHT, PAD = 110, 6
#: colours: the equivalent diameter, the min-max band, the eye's line, a lesion's mark
LINE, BAND, EYE, MARK = QColor(240, 200, 80), QColor(240, 200, 80, 60), QColor(90, 200, 255), QColor(255, 90, 90)


def section_text(profile, k: int) -> str:
    """One line of section ``k``'s numbers (mm to 0.1)."""
    s = profile.sections
    return (f"{profile.centerline.arc[k]:.1f} mm along: area {s.area[k]:.1f} mm², diameter {s.diameter[k]:.1f} mm "
            f"(min {s.min_diameter[k]:.1f}, max {s.max_diameter[k]:.1f}), inscribed radius "
            f"{s.inscribed_radius[k]:.1f} mm")


class _Plot(QWidget):
    """The curves (see the module docstring)."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.profile = None
        self.arc: float | None = None
        self.setMinimumHeight(HEIGHT)

    def _xy(self, s, d) -> tuple[np.ndarray, np.ndarray]:
        p = self.profile
        top = float(np.nanmax(p.sections.max_diameter)) or 1.0
        w, h = self.width() - 2 * PAD, self.height() - 2 * PAD
        x = PAD + w * np.asarray(s, float) / max(p.length, 1e-9)
        y = PAD + h * (1.0 - np.asarray(d, float) / top)
        return x, y

    def _poly(self, s, d) -> QPolygonF:
        x, y = self._xy(s, d)
        return QPolygonF([QPointF(float(a), float(b)) for a, b in zip(x, y, strict=True)])

    def paintEvent(self, event):  # noqa: N802 (Qt's name)
        painter = QPainter(self)
        painter.fillRect(self.rect(), QColor(25, 25, 28))
        p = self.profile
        if p is not None and len(p.centerline.arc) > 1:
            arc, sec = p.centerline.arc, p.sections
            band = self._poly(np.concatenate([arc, arc[::-1]]),
                              np.concatenate([sec.max_diameter, sec.min_diameter[::-1]]))
            painter.setPen(Qt.NoPen)
            painter.setBrush(BAND)
            painter.drawPolygon(band)
            painter.setPen(QPen(LINE, 2))
            painter.drawPolyline(self._poly(arc, sec.diameter))
            for lesion in (p.stenosis, p.maximum):
                if lesion is not None:
                    painter.setPen(QPen(MARK, 1))
                    x, _ = self._xy(lesion.arc, 0.0)
                    painter.drawLine(QPointF(float(x), PAD), QPointF(float(x), self.height() - PAD))
            painter.setPen(QPen(QColor(200, 200, 200), 1))
            top = float(np.nanmax(sec.max_diameter))
            painter.drawText(PAD + 2, PAD + 12, f"{top:.1f} mm")
            text = f"{p.length:.1f} mm along"
            painter.drawText(self.width() - PAD - painter.fontMetrics().horizontalAdvance(text) - 2,
                             self.height() - PAD - 2, text)
            if self.arc is not None:
                painter.setPen(QPen(EYE, 2))
                x, _ = self._xy(self.arc, 0.0)
                painter.drawLine(QPointF(float(x), 0.0), QPointF(float(x), float(self.height())))
        painter.end()


class ProfileView(QWidget):
    """The profile plot and the current section's numbers (see the module docstring)."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.plot = _Plot()
        self.label = QLabel("")
        self.label.setWordWrap(True)
        lay = QVBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.addWidget(self.plot)
        lay.addWidget(self.label)

    def set_profile(self, profile) -> None:
        """Show ``profile`` (None: nothing), the eye at its start."""
        self.plot.profile = profile
        self.label.setText("" if profile is None else str(profile))
        self.set_eye(None)

    def set_eye(self, point) -> int | None:
        """The eye at ``point`` (world mm; None: none): its section's numbers shown; returns that section."""
        p = self.plot.profile
        if p is None or point is None:
            self.plot.arc = None
            self.plot.update()
            return None
        arc, _ = p.centerline.project(np.asarray(point, float))
        k = int(np.argmin(np.abs(p.centerline.arc - arc)))
        self.plot.arc = arc
        self.label.setText(section_text(p, k))
        self.plot.update()
        return k
