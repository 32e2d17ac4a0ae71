"""A slice view: one plane of the volume in radiological orientation, linked to the others.

* wheel (or Page Up/Down): the next or previous slice (the crosshair moves along the normal);
* left click or drag: move the crosshair (all views follow, the 3D view shows it);
* right drag: window (horizontal) and level (vertical);
* left drag on an edge of the crop box: move that face of the box;
* in a pick mode (seeds for region growing, endoscopy start/end) a left click
  reports the world point to ``picked`` instead;
* rulers and regions: placed, moved and deleted by ``measure_tool`` (``_measure_tool``), which takes a press
  first.

Overlays: the segmentation mask (red), seeds, the crop box, the endoscopy
start, end and centerline, the 3D camera's position (cyan), and the measurements with their values (yellow).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from PySide6.QtCore import QPointF, QRectF, Qt, Signal
from PySide6.QtGui import QColor, QImage, QPainter, QPen, QPolygonF
from PySide6.QtWidgets import QWidget

from ..core import Window, table_range, window_to_uint8
from ._measure_tool import MeasureTool
from ._slice_geometry import DISPLAY_AXES, SliceGeometry

__all__ = ["SliceView"]

_LABELS = {"axial": ("R", "L", "A", "P"), "coronal": ("R", "L", "S", "I"), "sagittal": ("A", "P", "S", "I")}
_AXIS_COLOURS = (QColor(230, 80, 80), QColor(80, 200, 80), QColor(90, 140, 255))  # x, y, z lines


class SliceView(QWidget):
    """One of the axial, coronal and sagittal views of an :class:`AppState`.

    Signals
    -------
    picked(str plane, object world)
        A left click in a pick mode (``pick_mode`` not None), with the world point (3,) mm.
    """

    picked = Signal(str, object)

    def __init__(self, state, plane: str, parent=None):
        super().__init__(parent)
        self.state = state
        self.plane = plane
        self.pick_mode: str | None = None
        self.endoscopy = None  # an Endoscopy model, drawn when set
        self.geometry_: SliceGeometry | None = None
        self._cache: tuple | None = None
        self._image: QImage | None = None
        self._mask_image: QImage | None = None
        self._drag: tuple | None = None
        self.measure_tool = MeasureTool(self)
        self.setMinimumSize(120, 120)
        self.setFocusPolicy(Qt.ClickFocus)
        self.setMouseTracking(True)
        for topic in ("volume", "crosshair", "window", "mask", "seeds", "camera", "crop", "endoscopy", "scene",
                      "measurements"):
            state.subscribe(topic, self._changed)
        self._changed()

    # -- model --------------------------------------------------------------
    @property
    def index(self) -> int:
        return self.geometry_.index_of(self.state.crosshair) if self.geometry_ else 0

    def _changed(self) -> None:
        can = self.state.canonical
        if can is None:
            self.geometry_ = None
        elif self.geometry_ is None or self.geometry_.volume is not can:
            self.geometry_ = SliceGeometry(can, self.plane)
        self.update()

    def _images(self) -> tuple[QImage, QImage | None]:
        g = self.geometry_
        key = (id(g.volume), self.index, self.state.window, id(self.state.mask_canonical))
        if self._cache != key:
            gray = window_to_uint8(g.image(self.index), self.state.window)
            if self.state.volume is not None and self.state.volume.meta.get("display_inverted"):
                gray = 255 - gray  # MONOCHROME1: low values white
            gray = self._gray = np.ascontiguousarray(gray)
            fmt = QImage.Format_RGB888 if gray.ndim == 3 else QImage.Format_Grayscale8  # colour volumes: RGB
            self._image = QImage(gray.data, gray.shape[1], gray.shape[0], gray.strides[0], fmt)
            self._mask_image = None
            if self.state.mask_canonical is not None:
                m = g.image(self.index, self.state.mask_canonical) > 0
                rgba = np.zeros(m.shape + (4,), np.uint8)
                rgba[m] = (255, 40, 40, 110)
                self._rgba = np.ascontiguousarray(rgba)
                self._mask_image = QImage(self._rgba.data, m.shape[1], m.shape[0], self._rgba.strides[0],
                                          QImage.Format_RGBA8888)
            self._cache = key
        return self._image, self._mask_image

    # -- display mapping ----------------------------------------------------
    def image_rect(self) -> QRectF:
        """Where the slice is drawn: the largest rectangle of the right physical aspect, centred."""
        g = self.geometry_
        w_mm, h_mm = g.cols * g.col_mm, g.rows * g.row_mm
        s = min(self.width() / w_mm, self.height() / h_mm)
        w, h = w_mm * s, h_mm * s
        return QRectF((self.width() - w) / 2, (self.height() - h) / 2, w, h)

    def to_widget(self, display_xy) -> np.ndarray:
        """Display pixels ``(..., 2)`` -> widget coordinates ``(..., 2)``."""
        r, g = self.image_rect(), self.geometry_
        d = np.asarray(display_xy, float)
        return np.stack([r.x() + d[..., 0] * r.width() / g.cols, r.y() + d[..., 1] * r.height() / g.rows], -1)

    def world_at(self, x: float, y: float) -> np.ndarray:
        """The world point (mm) under widget position ``(x, y)`` on the current slice."""
        r, g = self.image_rect(), self.geometry_
        col = (x - r.x()) * g.cols / r.width()
        row = (y - r.y()) * g.rows / r.height()
        return g.display_to_world(col, row, self.index)

    def world_to_widget(self, world) -> np.ndarray:
        return self.to_widget(self.geometry_.world_to_display(world))

    # -- painting -----------------------------------------------------------
    def paintEvent(self, event) -> None:  # noqa: N802 - Qt name
        p = QPainter(self)
        p.fillRect(self.rect(), Qt.black)
        if self.geometry_ is None:
            p.setPen(Qt.gray)
            p.drawText(self.rect(), Qt.AlignCenter, "no data")
            return
        img, mask = self._images()
        rect = self.image_rect()
        p.drawImage(rect, img)
        if mask is not None:
            p.drawImage(rect, mask)
        self._paint_crosshair(p, rect)
        self._paint_crop(p)
        self._paint_points(p)
        self.measure_tool.paint(p)
        self._paint_labels(p, rect)
        p.end()

    def _paint_crosshair(self, p: QPainter, rect: QRectF) -> None:
        cx, cy = self.world_to_widget(self.state.crosshair)
        col_ax, row_ax, _ = DISPLAY_AXES[self.plane]
        p.setPen(QPen(_AXIS_COLOURS[row_ax], 1))  # the vertical line runs along the row axis
        p.drawLine(QPointF(cx, rect.top()), QPointF(cx, rect.bottom()))
        p.setPen(QPen(_AXIS_COLOURS[col_ax], 1))
        p.drawLine(QPointF(rect.left(), cy), QPointF(rect.right(), cy))

    def crop_box(self) -> np.ndarray | None:
        """The crop box as world ``(2, 3)`` [lo, hi], or None."""
        clip = self.state.scene.clipping
        if clip.crop is None or clip.crop_space != "world":
            return None
        c = np.asarray(clip.crop, float).reshape(3, 2)
        return c.T.copy()

    def _paint_crop(self, p: QPainter) -> None:
        box = self.crop_box()
        if box is None:
            return
        a, b = self.world_to_widget(box[0]), self.world_to_widget(box[1])
        pen = QPen(QColor(255, 210, 0), 1.5, Qt.DashLine)
        p.setPen(pen)
        p.setBrush(Qt.NoBrush)
        p.drawRect(QRectF(QPointF(min(a[0], b[0]), min(a[1], b[1])), QPointF(max(a[0], b[0]), max(a[1], b[1]))))

    def _dot(self, p: QPainter, world, colour: QColor, r: float = 4.0) -> None:
        x, y = self.world_to_widget(world)
        p.setPen(QPen(Qt.black, 1))
        p.setBrush(colour)
        p.drawEllipse(QPointF(x, y), r, r)

    def _paint_points(self, p: QPainter) -> None:
        g = self.geometry_
        for s in self.state.seeds:
            if g.distance_to_slice(s, self.index) <= 1.0:
                self._dot(p, s, QColor(255, 150, 0))
        endo = self.endoscopy
        if endo is not None:
            if endo.centerline is not None:
                pts = self.world_to_widget(endo.centerline.points)
                p.setPen(QPen(QColor(255, 0, 255), 1.5))
                p.drawPolyline(QPolygonF([QPointF(x, y) for x, y in pts]))
            for pt, col in ((endo.start, QColor(0, 255, 0)), (endo.end, QColor(255, 0, 0))):
                if pt is not None:
                    self._dot(p, pt, col, 5.0)
        cam = self.state.camera
        if cam is not None and self.state.volume is not None:
            lo, hi = self.state.volume.bounds()
            eye = np.asarray(cam.position, float)
            if np.all(eye >= lo) and np.all(eye <= hi):
                self._dot(p, eye, QColor(0, 230, 255), 5.0)
                f = cam.basis()[2]
                a, b = self.world_to_widget(eye), self.world_to_widget(eye + f * 15.0)
                p.setPen(QPen(QColor(0, 230, 255), 2))
                p.drawLine(QPointF(*a), QPointF(*b))

    def _paint_labels(self, p: QPainter, rect: QRectF) -> None:
        left, right, top, bottom = _LABELS[self.plane]
        p.setPen(QColor(255, 220, 120))
        m = 4
        p.drawText(QRectF(rect.left() + m, rect.center().y() - 8, 20, 16), Qt.AlignLeft, left)
        p.drawText(QRectF(rect.right() - 20 - m, rect.center().y() - 8, 20, 16), Qt.AlignRight, right)
        p.drawText(QRectF(rect.center().x() - 10, rect.top() + m, 20, 16), Qt.AlignHCenter, top)
        p.drawText(QRectF(rect.center().x() - 10, rect.bottom() - 16 - m, 20, 16), Qt.AlignHCenter, bottom)
        w = self.state.window
        p.setPen(Qt.white)
        p.drawText(6, 16, f"{self.plane} {self.index + 1}/{self.geometry_.n_slices}")
        p.drawText(6, self.height() - 6, f"W {w.width:.0f}  L {w.level:.0f}")

    # -- interaction ----------------------------------------------------------
    def step_slice(self, n: int) -> None:
        """Move the crosshair ``n`` slices along the plane's normal."""
        g = self.geometry_
        if g is None:
            return
        ijk = g.volume.world_to_index(self.state.crosshair)
        ijk[g.normal_axis] = np.clip(np.rint(ijk[g.normal_axis]) + n, 0, g.n_slices - 1)
        self.state.set_crosshair(g.volume.index_to_world(ijk))

    def wheelEvent(self, event) -> None:  # noqa: N802 - Qt names the override
        steps = event.angleDelta().y() / 120
        if steps:
            self.step_slice(int(np.sign(steps) * max(1, round(abs(steps)))))
        event.accept()

    def keyPressEvent(self, event) -> None:  # noqa: N802 - Qt names the override
        if event.key() in (Qt.Key_PageUp, Qt.Key_Up):
            self.step_slice(1)
        elif event.key() in (Qt.Key_PageDown, Qt.Key_Down):
            self.step_slice(-1)
        else:
            super().keyPressEvent(event)

    def _crop_edge(self, x: float, y: float):
        """(world axis, 0 lo / 1 hi) of the crop face whose edge is within 6 px of ``(x, y)``, or None."""
        box = self.crop_box()
        if box is None:
            return None
        col_ax, row_ax, _ = DISPLAY_AXES[self.plane]
        best, best_d = None, 6.0
        for ax, coord in ((col_ax, 0), (row_ax, 1)):
            for side in (0, 1):
                pt = box.mean(axis=0)
                pt[ax] = box[side, ax]
                d = abs(self.world_to_widget(pt)[coord] - (x, y)[coord])
                if d < best_d:
                    best, best_d = (ax, side), d
        return best

    def mousePressEvent(self, event) -> None:  # noqa: N802 - Qt names the override
        if self.geometry_ is None:
            return
        x, y = event.position().x(), event.position().y()
        if self.pick_mode is None and self.measure_tool.press(x, y, event.button()):
            return
        if event.button() == Qt.LeftButton:
            edge = self._crop_edge(x, y)
            if edge is not None:
                self._drag = ("crop", edge)
            elif self.pick_mode is not None:
                self.picked.emit(self.pick_mode, self.world_at(x, y))
            else:
                self._drag = ("cross",)
                self.state.set_crosshair(self.world_at(x, y))
        elif event.button() == Qt.RightButton:
            lo, hi = table_range(self.state.volume)  # a fill or far outliers past it would make a drag leap
            self._drag = ("window", x, y, self.state.window, max(hi - lo, 1e-6) / 500.0)

    def mouseMoveEvent(self, event) -> None:  # noqa: N802 - Qt names the override
        x, y = event.position().x(), event.position().y()
        if self.measure_tool.move(x, y):
            return
        if self._drag is None:
            edge = self._crop_edge(x, y) if self.geometry_ else None
            col_ax = DISPLAY_AXES[self.plane][0]
            self.setCursor(Qt.ArrowCursor if edge is None else
                           (Qt.SizeHorCursor if edge[0] == col_ax else Qt.SizeVerCursor))
            return
        kind = self._drag[0]
        if kind == "cross":
            self.state.set_crosshair(self.world_at(x, y))
        elif kind == "window":
            _, x0, y0, w0, k = self._drag
            self.state.set_window(Window(level=w0.level - (y - y0) * k, width=max(w0.width + (x - x0) * 2 * k, k)))
        elif kind == "crop":
            ax, side = self._drag[1]
            w = self.world_at(x, y)
            clip = self.state.scene.clipping
            c = list(clip.crop)
            lo_v, hi_v = self.state.volume.bounds()
            v = float(np.clip(w[ax], lo_v[ax], hi_v[ax]))
            if side == 0:
                c[2 * ax] = min(v, c[2 * ax + 1])
            else:
                c[2 * ax + 1] = max(v, c[2 * ax])
            self.state.interacting = True
            self.state.update_scene(clipping=replace(clip, crop=tuple(c)))

    def mouseReleaseEvent(self, event) -> None:  # noqa: N802 - Qt names the override
        if self.measure_tool.release():
            return
        if self._drag is not None and self._drag[0] == "crop":
            self.state.interacting = False
            self.state.emit("scene")
        self._drag = None
