"""The render panel: technique, device, technique options, compositing mode, shading model, sampling,
brightness and stereo.

The technique and device boxes hold the names of ``volumen.render.TECHNIQUES``
and ``DEVICES`` (the words of the Python API and the command line); each
technique's choice options (``option_choices``: slicing precision, plane
distribution..., mesh shading) get a box shown while that technique is chosen.
Devices a technique cannot use are disabled; the OpenGL device (``gl``) and the
techniques that need it are enabled once the render worker reports that OpenGL
works, otherwise they stay disabled with the reason as tooltip. Modes and
shading models are read from ``volumen.core.MODES`` / ``SHADINGS`` at run time.
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
from ..render import DEVICES, TECHNIQUES, Technique, option_choices
from ._stereo import STEREO_MODES, Stereo

__all__ = ["RenderPanel", "MODE_LABELS", "cycle_shading"]

MODE_LABELS = {"composite": "DVR", "mip": "MIP", "minip": "MinIP", "average": "Average", "isosurface": "Isosurface"}


def cycle_shading(state) -> str:
    """Switch to the next shading model of ``SHADINGS`` (the key that cycles them); returns its name."""
    from ..core import SHADINGS as shadings  # read at run time: colleagues add models

    cur = state.scene.shading.mode
    nxt = shadings[(shadings.index(cur) + 1) % len(shadings)] if cur in shadings else shadings[0]
    state.update_scene(shading=replace(state.scene.shading, mode=nxt))
    return nxt


def _enable(box: QComboBox, row: int, ok: bool, tooltip: str) -> None:
    item = box.model().item(row)
    item.setEnabled(ok)
    item.setToolTip(tooltip)


class RenderPanel(QWidget):
    """Edits how the 3D view is drawn."""

    def __init__(self, state, parent=None):
        super().__init__(parent)
        self.state = state
        self._updating = False
        self.technique = QComboBox()
        for name, spec in TECHNIQUES.items():
            self.technique.addItem(name, name)
            self.technique.setItemData(self.technique.count() - 1, spec.description, Qt.ToolTipRole)
        self.device = QComboBox()
        for name in DEVICES:
            self.device.addItem(name, name)
        #: (technique, option) -> the box of its choices
        self.options = {(t, f): QComboBox() for t in TECHNIQUES for f, c in option_choices(t).items()
                        if isinstance(c, tuple)}
        for (t, f), box in self.options.items():
            box.addItems(list(option_choices(t)[f]))
            box.setToolTip(f"{t} option {f}")
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

        for w in (self.technique, self.device, *self.options.values(), self.mode, self.shading, self.stereo):
            w.currentIndexChanged.connect(self._apply)
        for w in (self.iso, self.spv, self.separation, self.convergence):
            w.valueChanged.connect(self._apply)
        self.jitter.toggled.connect(self._apply)
        self.brightness.valueChanged.connect(self._apply)

        look = self._look = QFormLayout()
        look.addRow("Technique", self.technique)
        look.addRow("Device", self.device)
        for (_, f), box in self.options.items():
            look.addRow(f.replace("_", " ").capitalize(), box)
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
        """Enable the OpenGL device and the techniques that run only there, or disable them with ``reason``."""
        self._raster = (ok, reason)
        for row, spec in enumerate(TECHNIQUES.values()):
            if spec.devices == ("gl",):
                _enable(self.technique, row, ok, spec.description if ok else reason)
        self._enable_devices()

    def _enable_devices(self) -> None:
        spec = TECHNIQUES[self.technique.currentData() or "raycast"]
        gl_ok, gl_reason = self._raster
        for row, name in enumerate(DEVICES):
            if name not in (*spec.devices, "auto"):
                _enable(self.device, row, False, f"{spec.name} runs on {', '.join(spec.devices)}")
            elif name == "gl":
                _enable(self.device, row, gl_ok, "" if gl_ok else gl_reason)
            else:
                _enable(self.device, row, True, "")

    def refresh(self) -> None:
        self._updating = True
        s, st = self.state.scene, self.state
        self.technique.setCurrentIndex(max(self.technique.findData(st.technique.name), 0))
        self.device.setCurrentIndex(max(self.device.findData(st.device), 0))
        self._enable_devices()
        for (t, f), box in self.options.items():
            self._look.setRowVisible(box, t == st.technique.name)
            if t == st.technique.name:
                box.setCurrentText(str(getattr(st.technique.options, f)))
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
            st.set_display(**self._technique(), brightness=self.brightness.value() / 100,
                           stereo=Stereo(mode=self.stereo.currentText(), eye_separation=self.separation.value(),
                                         convergence=conv if conv > 0 else None))

    def _technique(self) -> dict:
        """``technique`` (and ``device`` when the technique can use the chosen one) from the boxes."""
        st, name = self.state, self.technique.currentData() or "raycast"
        chosen = {f: box.currentText() for (t, f), box in self.options.items() if t == name}
        keep = st.technique.options if st.technique.name == name else None
        out = {"technique": Technique(name, keep, **(chosen if keep is not None else {}))}
        device = self.device.currentData()
        if device in (*TECHNIQUES[name].devices, "auto"):
            out["device"] = device
        return out
