"""The light editor: list, add at the camera (key J), delete, and edit the selected light.

Fields: kind (``LIGHT_KINDS`` of ``volumen.core._lighting``, read at run time), spot exponent,
intensity, colour, and "attached to the camera" (a flashlight that moves with
the view; its position and direction are then kept in the camera's frame).
Lights are also selected and moved in the 3D view.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from PySide6.QtGui import QColor
from PySide6.QtWidgets import (
    QCheckBox,
    QColorDialog,
    QComboBox,
    QDoubleSpinBox,
    QFormLayout,
    QHBoxLayout,
    QListWidget,
    QPushButton,
    QVBoxLayout,
    QWidget,
)

from ..core import Light
from ..core.gestures import light_at_camera

__all__ = ["LightPanel", "add_light_at_camera", "attach_light"]


def add_light_at_camera(state) -> int:
    """Add a spot light at the eye looking where the camera looks; lit shading is switched on if needed.

    Returns the new light's index.
    """
    from ..core import SHADINGS

    light = light_at_camera(state.camera)
    with state.batch():
        state.set_lights((*state.scene.lights, light), selected=len(state.scene.lights))
        if state.scene.shading.mode in ("none", "headlight") and "phong" in SHADINGS:
            state.update_scene(shading=replace(state.scene.shading, mode="phong"))
    return len(state.scene.lights) - 1


def attach_light(light: Light, camera, attached: bool) -> Light:
    """The same light expressed attached to the camera (offsets in its right/up/forward frame) or in the world."""
    if (light.attach == "camera") == attached:
        return light
    pos, d = light.in_world(camera)
    if not attached:
        return replace(light, position=tuple(pos), direction=tuple(d), attach="world")
    m = np.stack(camera.basis(), axis=1)  # columns right, up, forward
    rel = m.T @ (pos - np.asarray(camera.position, float))
    return replace(light, position=tuple(rel), direction=tuple(m.T @ d), attach="camera")


class LightPanel(QWidget):
    """Edits ``state.scene.lights``."""

    def __init__(self, state, parent=None):
        from ..core._scene import LIGHT_KINDS

        super().__init__(parent)
        self.state = state
        self.list = QListWidget()
        self.list.currentRowChanged.connect(self._select)
        add = QPushButton("Add at camera (J)")
        add.clicked.connect(lambda: add_light_at_camera(state))
        delete = QPushButton("Delete")
        delete.clicked.connect(self.delete_selected)
        self.kind = QComboBox()
        self.kind.addItems(list(LIGHT_KINDS))
        self.exponent = QDoubleSpinBox(minimum=0.0, maximum=200.0, singleStep=1.0)
        self.intensity = QDoubleSpinBox(minimum=0.0, maximum=20.0, singleStep=0.1)
        self.colour = QPushButton("Colour...")
        self.attached = QCheckBox("Attached to the camera (flashlight)")
        self.kind.currentTextChanged.connect(lambda v: self._edit(kind=v))
        self.exponent.valueChanged.connect(lambda v: self._edit(exponent=v))
        self.intensity.valueChanged.connect(lambda v: self._edit(intensity=v))
        self.colour.clicked.connect(self._pick_colour)
        self.attached.toggled.connect(self._attach)
        row = QHBoxLayout()
        row.addWidget(add)
        row.addWidget(delete)
        form = QFormLayout()
        form.addRow("Kind", self.kind)
        form.addRow("Spot exponent", self.exponent)
        form.addRow("Intensity", self.intensity)
        form.addRow("", self.colour)
        form.addRow("", self.attached)
        lay = QVBoxLayout(self)
        lay.addWidget(self.list)
        lay.addLayout(row)
        lay.addLayout(form)
        lay.addStretch(1)
        self._updating = False
        state.subscribe("scene", self.refresh)
        state.subscribe("selection", self.refresh)
        self.refresh()

    def refresh(self) -> None:
        """Show the lights and the selected one's fields."""
        self._updating = True
        lights = self.state.scene.lights
        if self.list.count() != len(lights):
            self.list.clear()
            self.list.addItems([f"Light {n + 1}" for n in range(len(lights))])
        for n, lt in enumerate(lights):
            self.list.item(n).setText(f"Light {n + 1}: {lt.kind}{' (camera)' if lt.attach == 'camera' else ''}")
        sel = self.state.selected_light
        self.list.setCurrentRow(-1 if sel is None else sel)
        has = sel is not None and sel < len(lights)
        for w in (self.kind, self.exponent, self.intensity, self.colour, self.attached):
            w.setEnabled(has)
        if has:
            lt = lights[sel]
            self.kind.setCurrentText(lt.kind)
            self.exponent.setValue(lt.exponent)
            self.intensity.setValue(lt.intensity)
            self.attached.setChecked(lt.attach == "camera")
        self._updating = False

    def _select(self, row: int) -> None:
        if not self._updating:
            self.state.select_light(None if row < 0 else row)

    def _edit(self, **changes) -> None:
        sel = self.state.selected_light
        if self._updating or sel is None:
            return
        self.state.replace_light(sel, replace(self.state.scene.lights[sel], **changes))

    def _attach(self, on: bool) -> None:
        sel = self.state.selected_light
        if self._updating or sel is None:
            return
        self.state.replace_light(sel, attach_light(self.state.scene.lights[sel], self.state.camera, on))

    def _pick_colour(self) -> None:
        sel = self.state.selected_light
        if sel is None:
            return
        c = QColorDialog.getColor(QColor.fromRgbF(*[min(1.0, v) for v in self.state.scene.lights[sel].color]), self)
        if c.isValid():
            self._edit(color=(c.redF(), c.greenF(), c.blueF()))

    def delete_selected(self) -> None:
        sel = self.state.selected_light
        if sel is None:
            return
        lights = list(self.state.scene.lights)
        del lights[sel]
        self.state.set_lights(lights, selected=None)
