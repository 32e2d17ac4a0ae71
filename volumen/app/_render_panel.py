"""The render panel: technique, compositing mode, shading model, sampling, brightness and stereo.

Techniques are the backends of ``volumen.render.BACKENDS``: ray casting
(``cpu``), texture slicing (``slicing``) and mesh (``mesh``); the OpenGL ones
are enabled once the render worker reports that OpenGL works, otherwise they
stay disabled with the reason as tooltip. Modes and shading models are read
from ``volumen.core.MODES`` / ``SHADINGS`` at run time.
"""

from __future__ import annotations

from dataclasses import replace

from PySide6.QtCore import Qt
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QDoubleSpinBox,
    QFormLayout,
    QGroupBox,
    QSlider,
    QVBoxLayout,
    QWidget,
)

from ..core import MODES, SHADINGS
from ._stereo import STEREO_MODES, Stereo

__all__ = ["RenderPanel", "TECHNIQUES", "MODE_LABELS", "cycle_shading"]

#: technique label -> backend name
TECHNIQUES = {"Ray casting": "cpu", "Texture slicing": "slicing", "Mesh (isosurface)": "mesh"}
MODE_LABELS = {"composite": "DVR", "mip": "MIP", "minip": "MinIP", "average": "Average", "isosurface": "Isosurface"}


def cycle_shading(state) -> str:
    """Switch to the next shading model of ``SHADINGS`` (the key that cycles them); returns its name."""
    from ..core import SHADINGS as shadings  # read at run time: colleagues add models

    cur = state.scene.shading.mode
    nxt = shadings[(shadings.index(cur) + 1) % len(shadings)] if cur in shadings else shadings[0]
    state.update_scene(shading=replace(state.scene.shading, mode=nxt))
    return nxt


class RenderPanel(QWidget):
    """Edits how the 3D view is drawn."""

    def __init__(self, state, parent=None):
        super().__init__(parent)
        self.state = state
        self._updating = False
        self.technique = QComboBox()
        for label, backend in TECHNIQUES.items():
            self.technique.addItem(label, backend)
        self.set_raster_available(False, "checking whether OpenGL works...")
        self.mode = QComboBox()
        for m in MODES:
            self.mode.addItem(MODE_LABELS.get(m, m), m)
        self.shading = QComboBox()
        self.shading.addItems(list(SHADINGS))
        self.shading.setToolTip("Shading model (key L cycles them)")
        self.iso = QDoubleSpinBox(minimum=-5000, maximum=10000, singleStep=10, decimals=0)
        self.spv = QDoubleSpinBox(minimum=0.1, maximum=16, singleStep=0.25, decimals=2)
        self.jitter = QCheckBox("Jitter ray starts")
        self.brightness = QSlider(Qt.Horizontal)
        self.brightness.setRange(10, 400)
        self.brightness.setToolTip("Display gain, percent")
        self.stereo = QComboBox()
        self.stereo.addItems(list(STEREO_MODES))
        self.separation = QDoubleSpinBox(minimum=0, maximum=500, singleStep=1, suffix=" mm")
        self.convergence = QDoubleSpinBox(minimum=0, maximum=10000, singleStep=10, suffix=" mm")
        self.convergence.setSpecialValueText("at the target")

        self.technique.currentIndexChanged.connect(self._apply)
        for w in (self.mode, self.shading, self.stereo):
            w.currentIndexChanged.connect(self._apply)
        for w in (self.iso, self.spv, self.separation, self.convergence):
            w.valueChanged.connect(self._apply)
        self.jitter.toggled.connect(self._apply)
        self.brightness.valueChanged.connect(self._apply)

        look = QFormLayout()
        look.addRow("Technique", self.technique)
        look.addRow("Mode", self.mode)
        look.addRow("Shading", self.shading)
        look.addRow("Iso value", self.iso)
        look.addRow("Samples / voxel", self.spv)
        look.addRow("", self.jitter)
        look.addRow("Brightness", self.brightness)
        st = QGroupBox("Stereo")
        sf = QFormLayout(st)
        sf.addRow("Output", self.stereo)
        sf.addRow("Eye separation", self.separation)
        sf.addRow("Convergence", self.convergence)
        lay = QVBoxLayout(self)
        lay.addLayout(look)
        lay.addWidget(st)
        lay.addStretch(1)
        for topic in ("scene", "display", "volume"):
            state.subscribe(topic, self.refresh)
        self.refresh()

    def set_raster_available(self, ok: bool, reason: str) -> None:
        """Enable the OpenGL techniques, or disable them with ``reason`` as tooltip."""
        model = self.technique.model()
        for row in range(self.technique.count()):
            if self.technique.itemData(row) == "cpu":
                continue
            item = model.item(row)
            item.setEnabled(ok)
            item.setToolTip("" if ok else reason)

    def refresh(self) -> None:
        self._updating = True
        s, st = self.state.scene, self.state
        self.technique.setCurrentIndex(max(self.technique.findData(st.backend), 0))
        self.mode.setCurrentIndex(max(self.mode.findData(s.mode), 0))
        self.shading.setCurrentText(s.shading.mode)
        self.iso.setValue(s.isosurface.value)
        self.spv.setValue(s.sampling.samples_per_voxel)
        self.jitter.setChecked(s.sampling.jitter)
        self.brightness.setValue(int(round(st.brightness * 100)))
        self.stereo.setCurrentText(st.stereo.mode)
        self.separation.setValue(st.stereo.eye_separation)
        self.convergence.setValue(st.stereo.convergence or 0.0)
        self._updating = False

    def _apply(self, *_args) -> None:
        if self._updating:
            return
        s, st = self.state.scene, self.state
        with st.batch():
            st.update_scene(mode=self.mode.currentData(),
                            shading=replace(s.shading, mode=self.shading.currentText()),
                            isosurface=replace(s.isosurface, value=self.iso.value()),
                            sampling=replace(s.sampling, samples_per_voxel=self.spv.value(),
                                             jitter=self.jitter.isChecked()))
            conv = self.convergence.value()
            st.set_display(backend=self.technique.currentData() or "cpu", brightness=self.brightness.value() / 100,
                           stereo=Stereo(mode=self.stereo.currentText(), eye_separation=self.separation.value(),
                                         convergence=conv if conv > 0 else None))
