"""The clipping panel: a crop box (world mm, its faces also draggable in the slice views) and clip planes.

Clip planes are added through the crosshair: an axial, coronal or sagittal
plane, or one facing the camera (keeping what lies beyond it); the selected
plane can be flipped, moved along its normal or removed.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from PySide6.QtWidgets import (
    QCheckBox,
    QDoubleSpinBox,
    QGridLayout,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QListWidget,
    QPushButton,
    QVBoxLayout,
    QWidget,
)

from ..core import ClipPlane

__all__ = ["ClipPanel"]

_AXES = "xyz"


class ClipPanel(QWidget):
    """Edits ``state.scene.clipping``."""

    def __init__(self, state, parent=None):
        super().__init__(parent)
        self.state = state
        self._updating = False
        self.crop_on = QCheckBox("Crop box (drag its edges in the slice views)")
        self.crop_on.toggled.connect(self._toggle_crop)
        grid = QGridLayout()
        self.spins = []
        for a, name in enumerate(_AXES):
            grid.addWidget(QLabel(f"{name} (mm)"), a, 0)
            pair = []
            for side in range(2):
                sp = QDoubleSpinBox(minimum=-1e5, maximum=1e5, decimals=1, singleStep=2.0)
                sp.valueChanged.connect(self._spin)
                grid.addWidget(sp, a, 1 + side)
                pair.append(sp)
            self.spins.append(pair)
        box = QGroupBox("Crop")
        bl = QVBoxLayout(box)
        bl.addWidget(self.crop_on)
        bl.addLayout(grid)

        self.planes = QListWidget()
        buttons = QHBoxLayout()
        for label, kind in (("Axial", 2), ("Coronal", 1), ("Sagittal", 0), ("Facing view", "view")):
            b = QPushButton(label)
            b.clicked.connect(lambda _=False, k=kind: self.add_plane(k))
            buttons.addWidget(b)
        flip = QPushButton("Flip")
        flip.clicked.connect(self._flip)
        remove = QPushButton("Remove")
        remove.clicked.connect(self._remove)
        self.offset = QDoubleSpinBox(minimum=-1000, maximum=1000, singleStep=2.0, suffix=" mm")
        self.offset.setToolTip("Move the selected plane along its normal")
        self.offset.valueChanged.connect(self._move)
        row = QHBoxLayout()
        row.addWidget(flip)
        row.addWidget(remove)
        row.addWidget(self.offset)
        pbox = QGroupBox("Clip planes (through the crosshair)")
        pl = QVBoxLayout(pbox)
        pl.addLayout(buttons)
        pl.addWidget(self.planes)
        pl.addLayout(row)
        lay = QVBoxLayout(self)
        lay.addWidget(box)
        lay.addWidget(pbox)
        lay.addStretch(1)
        self.planes.currentRowChanged.connect(lambda _r: self._sync_offset())
        self._plane_base: ClipPlane | None = None
        state.subscribe("scene", self.refresh)
        state.subscribe("volume", self.refresh)
        self.refresh()

    def refresh(self) -> None:
        self._updating = True
        clip = self.state.scene.clipping
        on = clip.crop is not None and clip.crop_space == "world"
        self.crop_on.setChecked(on)
        c = np.asarray(clip.crop, float).reshape(3, 2) if on else None
        for a in range(3):
            for side in range(2):
                self.spins[a][side].setEnabled(on)
                if on:
                    self.spins[a][side].setValue(c[a, side])
        if self.planes.count() != len(clip.planes):
            self.planes.clear()
        for n, pl in enumerate(clip.planes):
            text = f"point {np.round(pl.point, 1).tolist()} normal {np.round(pl.normal, 2).tolist()}"
            if n < self.planes.count():
                self.planes.item(n).setText(text)
            else:
                self.planes.addItem(text)
        self._updating = False

    def _set(self, **changes) -> None:
        self.state.update_scene(clipping=replace(self.state.scene.clipping, **changes))

    def _toggle_crop(self, on: bool) -> None:
        if self._updating or self.state.volume is None:
            return
        if on:
            lo, hi = self.state.volume.bounds()
            self._set(crop=(lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]), crop_space="world")
        else:
            self._set(crop=None)

    def _spin(self) -> None:
        if self._updating or not self.crop_on.isChecked():
            return
        c = []
        for a in range(3):
            lo, hi = self.spins[a][0].value(), self.spins[a][1].value()
            c += [min(lo, hi), max(lo, hi)]
        self._set(crop=tuple(c), crop_space="world")

    def add_plane(self, kind) -> None:
        """Add a clip plane through the crosshair: world axis 0/1/2 (keeps the + side) or ``"view"``."""
        planes = self.state.scene.clipping.planes
        if len(planes) >= 6:
            return
        if kind == "view":
            normal = self.state.camera.basis()[2]
        else:
            normal = np.eye(3)[kind]
        plane = ClipPlane(point=tuple(self.state.crosshair), normal=tuple(normal))
        self._set(planes=(*planes, plane))
        self.planes.setCurrentRow(len(planes))

    def _selected(self) -> int | None:
        r = self.planes.currentRow()
        return r if 0 <= r < len(self.state.scene.clipping.planes) else None

    def _replace_plane(self, n: int, plane: ClipPlane) -> None:
        planes = list(self.state.scene.clipping.planes)
        planes[n] = plane
        self._set(planes=tuple(planes))

    def _flip(self) -> None:
        n = self._selected()
        if n is not None:
            pl = self.state.scene.clipping.planes[n]
            self._replace_plane(n, replace(pl, normal=tuple(-np.asarray(pl.normal))))
            self._sync_offset()

    def _remove(self) -> None:
        n = self._selected()
        if n is not None:
            planes = list(self.state.scene.clipping.planes)
            del planes[n]
            self._set(planes=tuple(planes))

    def _sync_offset(self) -> None:
        n = self._selected()
        self._plane_base = None if n is None else self.state.scene.clipping.planes[n]
        self.offset.blockSignals(True)
        self.offset.setValue(0.0)
        self.offset.blockSignals(False)

    def _move(self, mm: float) -> None:
        n = self._selected()
        if n is None or self._plane_base is None:
            return
        base = self._plane_base
        d = np.asarray(base.normal) / np.linalg.norm(base.normal)
        self._replace_plane(n, replace(base, point=tuple(np.asarray(base.point) + d * mm)))
