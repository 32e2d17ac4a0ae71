"""The transfer-function editor: histogram (log scale), draggable opacity points and colour stops, presets, shift.

* plot area: the volume's histogram (``log(1 + count)``, grey), the opacity
  curve with its points (drag to move; double-click to add; right-click to remove);
* colour bar below it: the colour ramp with its stops (drag to move;
  double-click a stop to choose its colour; double-click elsewhere to add one;
  right-click to remove);
* presets (``volumen.core.PRESETS``) and a shift slider (``TransferFunction.shifted``).

Every change goes straight into the state's scene, so the picture updates live
(at the reduced viewport while dragging).
"""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QPointF, QRectF, Qt
from PySide6.QtGui import QColor, QLinearGradient, QPainter, QPen, QPolygonF
from PySide6.QtWidgets import QColorDialog, QComboBox, QFormLayout, QLabel, QSlider, QVBoxLayout, QWidget

from ..core import PRESETS, TransferFunction, fitted_preset, table_range
from . import _tf_edit as edit

__all__ = ["TransferFunctionEditor", "TransferCanvas"]

_BAR = 22  # colour bar height, px
_PAD = 6


class TransferCanvas(QWidget):
    """The plot of the editor (see the module docstring)."""

    def __init__(self, state, parent=None):
        super().__init__(parent)
        self.state = state
        self.setMinimumSize(220, 150)
        self._hist = None
        self._drag: tuple | None = None
        state.subscribe("volume", self._new_volume)
        state.subscribe("scene", self.update)
        self._new_volume()

    def _new_volume(self) -> None:
        v = self.state.volume
        if v is not None:
            lo, hi = table_range(v)  # the renderers' table: a fill or far outliers past it would crowd the editor
            self.range = (lo, hi if hi > lo else lo + 1.0)
            self._hist = edit.log_histogram(v, value_range=self.range)
        self.update()

    # -- geometry -------------------------------------------------------------
    def plot_rect(self) -> QRectF:
        return QRectF(_PAD, _PAD, self.width() - 2 * _PAD, self.height() - 3 * _PAD - _BAR)

    def bar_rect(self) -> QRectF:
        r = self.plot_rect()
        return QRectF(r.left(), r.bottom() + _PAD, r.width(), _BAR)

    def x_of(self, value) -> np.ndarray:
        lo, hi = self.range
        r = self.plot_rect()
        return r.left() + (np.asarray(value, float) - lo) / (hi - lo) * r.width()

    def value_of(self, x: float) -> float:
        lo, hi = self.range
        r = self.plot_rect()
        return lo + (x - r.left()) / r.width() * (hi - lo)

    def y_of(self, alpha) -> np.ndarray:
        r = self.plot_rect()
        return r.bottom() - np.asarray(alpha, float) * r.height()

    def _opacity_hit(self, x: float, y: float) -> int | None:
        tf = self.state.scene.transfer
        pts = np.array(tf.opacity)
        d = np.hypot(self.x_of(pts[:, 0]) - x, self.y_of(pts[:, 1]) - y)
        i = int(np.argmin(d))
        return i if d[i] <= 7 else None

    def _color_hit(self, x: float) -> int | None:
        tf = self.state.scene.transfer
        xs = self.x_of([p[0] for p in tf.color])
        i = int(np.argmin(np.abs(xs - x)))
        return i if abs(xs[i] - x) <= 6 else None

    # -- painting -------------------------------------------------------------
    def paintEvent(self, event) -> None:  # noqa: N802 - Qt names the override
        p = QPainter(self)
        p.fillRect(self.rect(), QColor(30, 30, 34))
        if self.state.volume is None:
            p.end()
            return
        p.setRenderHint(QPainter.Antialiasing)
        r = self.plot_rect()
        heights, edges = self._hist
        xs = self.x_of(edges)
        p.setPen(Qt.NoPen)
        p.setBrush(QColor(110, 110, 110))
        for h, x0, x1 in zip(heights, xs[:-1], xs[1:], strict=True):
            p.drawRect(QRectF(x0, r.bottom() - h * r.height(), max(x1 - x0, 1.0), h * r.height()))
        tf = self.state.scene.transfer
        lo, hi = self.range
        xs_fine = np.linspace(lo, hi, 200)
        alpha = tf.evaluate(xs_fine)[:, 3]
        p.setPen(QPen(QColor(255, 255, 255), 1.5))
        p.drawPolyline(QPolygonF([QPointF(x, y) for x, y in zip(self.x_of(xs_fine), self.y_of(alpha), strict=True)]))
        p.setPen(QPen(Qt.black, 1))
        for v, a in tf.opacity:
            if lo <= v <= hi:
                p.setBrush(QColor(255, 255, 255))
                p.drawEllipse(QPointF(float(self.x_of(v)), float(self.y_of(a))), 4.5, 4.5)
        bar = self.bar_rect()
        grad = QLinearGradient(bar.left(), 0, bar.right(), 0)
        for v, rgb in zip(xs_fine[::10], tf.evaluate(xs_fine[::10])[:, :3], strict=True):
            grad.setColorAt(float((v - lo) / (hi - lo)), QColor.fromRgbF(*[float(c) for c in rgb]))
        p.fillRect(bar, grad)
        for v, *rgb in tf.color:
            if lo <= v <= hi:
                x = float(self.x_of(v))
                p.setBrush(QColor.fromRgbF(*rgb))
                p.setPen(QPen(Qt.white, 1.5))
                p.drawPolygon(QPolygonF([QPointF(x, bar.top()), QPointF(x - 5, bar.bottom()),
                                         QPointF(x + 5, bar.bottom())]))
        p.setPen(QColor(200, 200, 200))
        p.drawText(QRectF(r.left() + 2, r.top(), r.width() - 4, 14), Qt.AlignLeft, f"{lo:.0f}")
        p.drawText(QRectF(r.left() + 2, r.top(), r.width() - 4, 14), Qt.AlignRight, f"{hi:.0f}")
        p.end()

    # -- mouse ----------------------------------------------------------------
    def _set(self, tf: TransferFunction, interactive: bool = True) -> None:
        self.state.interacting = interactive
        self.state.update_scene(transfer=tf)

    def mousePressEvent(self, event) -> None:  # noqa: N802 - Qt names the override
        if self.state.volume is None:
            return
        x, y = event.position().x(), event.position().y()
        tf = self.state.scene.transfer
        in_bar = y >= self.bar_rect().top()
        if event.button() == Qt.RightButton:
            if in_bar and (i := self._color_hit(x)) is not None:
                self._set(edit.remove_color_stop(tf, i), False)
            elif not in_bar and (i := self._opacity_hit(x, y)) is not None:
                self._set(edit.remove_opacity_point(tf, i), False)
            return
        if event.button() == Qt.LeftButton:
            if in_bar:
                i = self._color_hit(x)
                self._drag = ("color", i) if i is not None else None
            else:
                i = self._opacity_hit(x, y)
                self._drag = ("opacity", i) if i is not None else None

    def mouseMoveEvent(self, event) -> None:  # noqa: N802 - Qt names the override
        if self._drag is None:
            return
        x, y = event.position().x(), event.position().y()
        tf = self.state.scene.transfer
        kind, i = self._drag
        r = self.plot_rect()
        if kind == "opacity":
            alpha = (r.bottom() - y) / r.height()
            self._set(edit.move_opacity_point(tf, i, self.value_of(x), alpha))
        else:
            self._set(edit.move_color_stop(tf, i, self.value_of(x)))

    def mouseReleaseEvent(self, event) -> None:  # noqa: N802 - Qt names the override
        if self._drag is not None:
            self._drag = None
            self._set(self.state.scene.transfer, False)

    def mouseDoubleClickEvent(self, event) -> None:  # noqa: N802 - Qt names the override
        x, y = event.position().x(), event.position().y()
        tf = self.state.scene.transfer
        if y >= self.bar_rect().top():
            i = self._color_hit(x)
            if i is None:
                tf, i = edit.add_color_stop(tf, self.value_of(x))
                self._set(tf, False)
            rgb = tf.color[i][1:]
            c = QColorDialog.getColor(QColor.fromRgbF(*rgb), self, "Colour stop")
            if c.isValid():
                self._set(edit.set_color_stop(self.state.scene.transfer, i, (c.redF(), c.greenF(), c.blueF())), False)
        else:
            r = self.plot_rect()
            tf, _ = edit.add_opacity_point(tf, self.value_of(x), (r.bottom() - y) / r.height())
            self._set(tf, False)


class TransferFunctionEditor(QWidget):
    """Canvas plus presets and shift (see the module docstring)."""

    def __init__(self, state, parent=None):
        super().__init__(parent)
        self.state = state
        self.canvas = TransferCanvas(state, self)
        self.presets = QComboBox()
        self.presets.addItem("(choose a preset)")
        self.presets.addItems(list(PRESETS))
        self.presets.activated.connect(self._preset)
        self.shift = QSlider(Qt.Horizontal)
        self.shift.setRange(-500, 500)
        self.shift.setToolTip("Move the inner control points (data units); the ends stay")
        self.shift.sliderPressed.connect(self._shift_start)
        self.shift.valueChanged.connect(self._shift)
        self.shift.sliderReleased.connect(self._shift_end)
        self._base = None
        form = QFormLayout()
        form.addRow("Preset", self.presets)
        form.addRow("Shift", self.shift)
        lay = QVBoxLayout(self)
        lay.addWidget(self.canvas, 1)
        lay.addLayout(form)
        lay.addWidget(QLabel("Drag points; double-click adds, right-click removes;\n"
                             "double-click a colour stop to change its colour."))

    def apply_preset(self, name: str) -> None:
        """Set the named preset (``volumen.core.PRESETS``)."""
        v = self.state.volume
        tf = fitted_preset(name, v) if v is not None else TransferFunction.preset(name)
        self.state.interacting = False
        self.state.update_scene(transfer=tf)
        self._base = None
        self.shift.blockSignals(True)
        self.shift.setValue(0)
        self.shift.blockSignals(False)

    def _preset(self, index: int) -> None:
        if index > 0:
            self.apply_preset(self.presets.itemText(index))

    def _shift_start(self) -> None:
        self._base = self.state.scene.transfer

    def _shift(self, value: int) -> None:
        if self._base is None:
            self._base = self.state.scene.transfer
        self.state.interacting = self.shift.isSliderDown()
        self.state.update_scene(transfer=self._base.shifted(float(value)))

    def _shift_end(self) -> None:
        self.state.interacting = False
        self.state.emit("scene")
