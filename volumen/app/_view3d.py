"""The 3D view: shows the worker's frames and turns mouse gestures into camera and light changes.

Mouse: left drag orbits, Shift+left or middle drag pans, right drag or the
wheel zooms. On a light's cone (the one under the mouse is drawn larger),
left drag moves the light in the view plane and Ctrl+left drag aims it.
While a drag lasts ``state.interacting`` is True (frames at a reduced
viewport). In endoscopic flight, left drag turns the view instead.

Overlay (QPainter, through ``Camera.project``): lights as cones pointing
where they shine, the crosshair's axes, the endoscopy centerline, a red frame
and "blocked" when a flight move hit the wall, and the frame time.
"""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QPointF, QRectF, Qt, QTimer, Signal
from PySide6.QtGui import QColor, QImage, QPainter, QPen, QPolygonF
from PySide6.QtWidgets import QWidget

from ..core import gestures
from ._overlays import crosshair_lines, light_cone, pick_light, project_polyline
from ._ruler3d import Ruler3D

__all__ = ["View3D"]

_AXIS_COLOURS = (QColor(230, 80, 80), QColor(80, 200, 80), QColor(90, 140, 255))


class View3D(QWidget):
    """The 3D view of an :class:`AppState`.

    Signals
    -------
    interaction_finished()
        A drag ended (the controller then asks for the full picture).
    fly_turn(float yaw, float pitch)
        A drag in endoscopic flight (degrees).
    """

    interaction_finished = Signal()
    fly_turn = Signal(float, float)

    def __init__(self, state, parent=None):
        super().__init__(parent)
        self.state = state
        self.frame = None
        self._qimage: QImage | None = None
        self.hover_light: int | None = None
        self.flying = False
        self.centerline = None
        self.blocked_marker = False
        self.status_text = ""
        self._drag: tuple | None = None
        self.ruler3d = Ruler3D(self)
        self._blocked_timer = QTimer(self, singleShot=True, interval=800)
        self._blocked_timer.timeout.connect(self._clear_blocked)
        self.setMinimumSize(160, 160)
        self.setMouseTracking(True)
        self.setFocusPolicy(Qt.StrongFocus)
        for topic in ("camera", "scene", "selection", "crosshair", "endoscopy", "measurements"):
            state.subscribe(topic, self.update)

    @property
    def view_size(self) -> tuple[int, int]:
        """``(width, height)`` in pixels of the pictures this view asks for."""
        return max(self.width(), 1), max(self.height(), 1)

    # -- frames ---------------------------------------------------------------
    def show_frame(self, frame) -> None:
        """Display a finished :class:`~volumen.app._view_picture.ViewPicture`."""
        self.frame = frame
        rgb = np.ascontiguousarray(frame.rgb)
        self._rgb = rgb
        self._qimage = QImage(rgb.data, rgb.shape[1], rgb.shape[0], rgb.strides[0], QImage.Format_RGB888)
        self.update()

    def show_blocked(self) -> None:
        """Flash the 'blocked' marker (a flight move hit the wall)."""
        self.blocked_marker = True
        self._blocked_timer.start()
        self.update()

    def _clear_blocked(self) -> None:
        self.blocked_marker = False
        self.update()

    # -- painting -------------------------------------------------------------
    def light_length(self) -> float:
        v = self.state.volume
        return 0.08 * v.diagonal if v is not None else 20.0

    def paintEvent(self, event) -> None:  # noqa: N802 - Qt names the override
        p = QPainter(self)
        p.fillRect(self.rect(), Qt.black)
        if self._qimage is not None:
            p.drawImage(QRectF(0, 0, self.width(), self.height()), self._qimage)
        cam = self.state.camera
        if cam is not None and self.state.volume is not None and self.state.stereo.mode == "off":
            p.setRenderHint(QPainter.Antialiasing)
            size = self.view_size
            if not self.flying:
                for ax, seg in crosshair_lines(self.state.volume, self.state.crosshair, cam, size):
                    p.setPen(QPen(_AXIS_COLOURS[ax], 1, Qt.DotLine))
                    p.drawLine(QPointF(*seg[0]), QPointF(*seg[1]))
            if self.centerline is not None:
                p.setPen(QPen(QColor(255, 0, 255), 2))
                for run in project_polyline(self.centerline.points, cam, size):
                    p.drawPolyline(QPolygonF([QPointF(x, y) for x, y in run]))
            self._paint_lights(p, cam, size)
            self.ruler3d.paint(p, cam, size)
        self._paint_text(p)
        p.end()

    def _paint_lights(self, p: QPainter, cam, size) -> None:
        for n, light in enumerate(self.state.scene.lights):
            if light.kind == "headlight" or light.attach == "camera":
                continue
            big = n == self.hover_light
            cone = light_cone(light, cam, size, self.light_length(), scale=1.6 if big else 1.0)
            if not cone.visible:
                continue
            sel = n == self.state.selected_light
            colour = QColor.fromRgbF(*[min(1.0, c) for c in light.color])
            p.setPen(QPen(QColor(255, 230, 0) if sel else Qt.white, 2.5 if (sel or big) else 1.5))
            colour.setAlphaF(0.55)
            p.setBrush(colour)
            p.drawPolygon(QPolygonF([QPointF(x, y) for x, y in cone.outline]))
            p.drawPolyline(QPolygonF([QPointF(x, y) for x, y in np.vstack([cone.rim, cone.rim[:1]])]))
            p.setBrush(Qt.white)
            p.drawEllipse(QPointF(*cone.apex), 3.0, 3.0)

    def _paint_text(self, p: QPainter) -> None:
        if self.blocked_marker:
            p.setPen(QPen(QColor(255, 40, 40), 6))
            p.setBrush(Qt.NoBrush)
            p.drawRect(self.rect().adjusted(3, 3, -3, -3))
            p.drawText(QRectF(0, 10, self.width(), 20), Qt.AlignHCenter, "blocked")
        f = self.frame
        p.setPen(Qt.white)
        if f is not None:
            res = "" if f.fraction >= 1 else f"  1/{round(1 / f.fraction)} res"
            spp = f"  {f.spp} spp" if f.spp else ""
            aside = "  OpenGL while the CPU kernel compiles" if f.stats.get("stand_in") else ""
            p.drawText(6, self.height() - 6, f"{f.seconds * 1000:.0f} ms{res}{spp}{aside}")
        if self.status_text:
            p.drawText(6, 16, self.status_text)

    # -- mouse ----------------------------------------------------------------
    def mousePressEvent(self, event) -> None:  # noqa: N802 - Qt names the override
        cam = self.state.camera
        if cam is None:
            return
        pos = (event.position().x(), event.position().y())
        mods = event.modifiers()
        button = event.button()
        if self.flying and button == Qt.LeftButton:
            self._drag = ("fly", pos)
            return
        if button == Qt.LeftButton and self.ruler3d.press(*pos):
            return
        if button == Qt.LeftButton:
            hit = pick_light(self.state.scene.lights, cam, self.view_size, self.light_length(), pos)
            if hit is not None:
                self.state.select_light(hit)
                self._drag = ("aim" if mods & Qt.ControlModifier else "light", pos, hit)
            elif mods & Qt.ShiftModifier:
                self._drag = ("pan", pos)
            else:
                self._drag = ("orbit", pos)
        elif button == Qt.MiddleButton:
            self._drag = ("pan", pos)
        elif button == Qt.RightButton:
            self._drag = ("zoom", pos)
        if self._drag is not None:
            self.state.interacting = True

    def mouseMoveEvent(self, event) -> None:  # noqa: N802 - Qt names the override
        pos = (event.position().x(), event.position().y())
        cam = self.state.camera
        if self._drag is None:
            if cam is not None and not self.flying:
                hit = pick_light(self.state.scene.lights, cam, self.view_size, self.light_length(), pos)
                if hit != self.hover_light:
                    self.hover_light = hit
                    self.update()
            return
        kind, last = self._drag[0], self._drag[1]
        dx, dy = pos[0] - last[0], pos[1] - last[1]
        self._drag = (kind, pos) + self._drag[2:]
        if kind == "fly":
            self.fly_turn.emit(-dx * gestures.DEGREES_PER_PIXEL * 0.5, -dy * gestures.DEGREES_PER_PIXEL * 0.5)
        elif kind == "orbit":
            self.state.set_camera(gestures.orbit(cam, dx, dy))
        elif kind == "pan":
            self.state.set_camera(gestures.pan(cam, dx, dy, self.view_size))
        elif kind == "zoom":
            self.state.set_camera(gestures.drag_zoom(cam, dy))
        elif kind in ("light", "aim"):
            n = self._drag[2]
            light = self.state.scene.lights[n]
            new = gestures.move_light(light, cam, dx, dy, self.view_size) if kind == "light" else \
                gestures.aim_light(light, cam, dx, dy)
            self.state.replace_light(n, new)

    def mouseReleaseEvent(self, event) -> None:  # noqa: N802 - Qt names the override
        if self._drag is not None:
            self._drag = None
            self.state.interacting = False
            self.interaction_finished.emit()

    def wheelEvent(self, event) -> None:  # noqa: N802 - Qt names the override
        cam = self.state.camera
        steps = event.angleDelta().y() / 120
        if cam is not None and steps and not self.flying:
            self.state.set_camera(gestures.wheel_zoom(cam, steps))
        event.accept()
