"""The measurement tool of a slice view: place, move and delete rulers and regions with the mouse.

* with a tool chosen (``SliceView.measure_tool.tool``: ruler, rectangle, ellipse), a left drag places one; its
  value is drawn beside it and follows the drag;
* a left drag on an end of a ruler or a corner of a region (within :data:`GRAB` px), in any mode, moves it;
* a right click on an end or corner deletes the measurement.

Every slice view draws each measurement its slice cuts (``_slice_measures.slice_part``): whole where it lies in
the slice, a cross where a ruler passes through it, the chord where a region does.
"""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QPointF, Qt
from PySide6.QtGui import QColor, QPen, QPolygonF

from ..errors import OutsideVolumeError
from ._slice_measures import TOOLS, caption, drag_to, grab, handles, slice_part, view_plane

__all__ = ["MeasureTool", "GRAB"]

#: how near (px) a press must be to a handle to grab it
GRAB = 7.0
_COLOUR = QColor(255, 235, 60)
_CUT = QColor(255, 235, 60, 150)


class MeasureTool:
    """The measurements of one :class:`~volumen.app._slice_view.SliceView`: mouse handling and drawing.

    Attributes
    ----------
    tool : str or None
        The tool a left drag places (one of ``TOOLS``), None to leave a left drag to the crosshair.
    captions : list of (str, (x, y))
        The values drawn at the last paint and where (widget px): what a user reads, and what the tests read.
    """

    def __init__(self, view):
        self.view = view
        self.tool: str | None = None
        self.captions: list[tuple[str, tuple[float, float]]] = []
        self._drag: list | None = None  # [measurement index (None: not placed yet), how to remake it (drag_to)]

    def set_tool(self, tool: str | None) -> None:
        if tool is not None and tool not in TOOLS:
            raise ValueError(f"tool must be one of {', '.join(TOOLS)} or None, got {tool!r}")
        self.tool = tool

    def _state(self):
        return self.view.state

    def _grabbed(self, x: float, y: float) -> tuple[int, int] | None:
        """(index, handle) of the handle shown on this slice nearest ``(x, y)`` within :data:`GRAB` px."""
        g, best, best_d = self.view.geometry_, None, GRAB
        for i, m in enumerate(self._state().measurements):
            if m.kind not in ("distance", "region") or slice_part(g, self.view.index, m) is None:
                continue
            for h, w in enumerate(handles(m)):
                d = float(np.hypot(*(self.view.world_to_widget(w) - (x, y))))
                if d < best_d:
                    best, best_d = (i, h), d
        return best

    # -- mouse --------------------------------------------------------------
    def press(self, x: float, y: float, button) -> bool:
        """Handle a press; True when the tool took it."""
        grabbed = self._grabbed(x, y)
        if button == Qt.RightButton and grabbed is not None:
            self._state().remove_measurement(grabbed[0])
            return True
        if button != Qt.LeftButton:
            return False
        if grabbed is not None:
            index, handle = grabbed
            self._drag = [index, grab(self._state().measurements[index], handle)]
            return True
        if self.tool is None:
            return False
        start = self.view.world_at(x, y)
        self._drag = [None, (self.tool, start, view_plane(self.view.geometry_, self.view.index), "", 1)]
        if self.tool == "ruler":
            self.move(x, y)
        return True

    def move(self, x: float, y: float) -> bool:
        """Follow the pointer with the handle dragged; a region is placed once it holds a voxel."""
        if self._drag is None:
            return False
        st, w = self._state(), self.view.world_at(x, y)
        index, recipe = self._drag
        try:
            m = drag_to(recipe, w, st.volume)
        except OutsideVolumeError:  # a region that holds no voxel yet (or any more): kept as it was
            return True
        self._drag[0] = st.put_measurement(index, m)
        return True

    def release(self) -> bool:
        taken, self._drag = self._drag is not None, None
        return taken

    # -- drawing --------------------------------------------------------------
    def paint(self, p) -> None:
        g = self.view.geometry_
        self.captions = []
        for m in self._state().measurements:
            if m.kind not in ("distance", "region"):
                continue
            part = slice_part(g, self.view.index, m)
            if part is None:
                continue
            kind, pts = part
            xy = self.view.world_to_widget(pts)
            if kind == "whole":
                self._whole(p, m, xy)
            else:
                self._cut(p, m, xy)

    def _whole(self, p, m, xy: np.ndarray) -> None:
        p.setPen(QPen(_COLOUR, 1.5))
        p.setBrush(Qt.NoBrush)
        line = QPolygonF([QPointF(x, y) for x, y in xy])
        p.drawPolyline(line) if m.kind == "distance" else p.drawPolygon(line)
        for hx, hy in self.view.world_to_widget(handles(m)):
            p.drawRect(int(hx) - 3, int(hy) - 3, 6, 6)
        self._caption(p, m, xy)

    def _cut(self, p, m, xy: np.ndarray) -> None:
        p.setPen(QPen(_CUT, 1.5, Qt.DashLine))
        if m.kind == "distance" or len(xy) == 1:
            for x, y in xy:
                p.drawLine(QPointF(x - 4, y - 4), QPointF(x + 4, y + 4))
                p.drawLine(QPointF(x - 4, y + 4), QPointF(x + 4, y - 4))
        else:
            p.drawPolyline(QPolygonF([QPointF(x, y) for x, y in xy]))
        if m.kind == "distance":  # a region's value is drawn where it lies whole, not beside every chord
            self._caption(p, m, xy)

    def _caption(self, p, m, xy: np.ndarray) -> None:
        text = caption(m)
        x, y = float(xy[:, 0].max()) + 6, float(xy[:, 1].min()) - 4
        x = max(0.0, min(x, self.view.width() - p.fontMetrics().horizontalAdvance(text) - 2))  # kept in the view
        while any(abs(y - cy) < 13 and abs(x - cx) < 120 for _, (cx, cy) in self.captions):
            y += 14  # below a caption already drawn there (two measurements cut at one place)
        p.setPen(Qt.black)
        p.drawText(QPointF(x + 1, y + 1), text)  # a shadow keeps it legible on bright tissue
        p.setPen(_COLOUR)
        p.drawText(QPointF(x, y), text)
        self.captions.append((text, (x, y)))
