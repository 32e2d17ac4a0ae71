"""The settings row of the notebook viewer: preset, mode, shading, lights and clipping.

Each control writes a new :class:`~volumen.core.Scene` through ``viewer.scene = ...`` (which
re-renders); :meth:`Controls.sync` shows a scene set from Python. The choices come from the core's
vocabularies (``PRESETS``, ``MODES``, ``SHADINGS``), so nothing is listed twice.
"""

from __future__ import annotations

import ipywidgets as widgets

from ..core import MODES, PRESETS, SHADINGS, Clipping, Shading, TransferFunction, fitted_preset, gestures

__all__ = ["Controls", "preset_transfer"]


def preset_transfer(scene, name: str) -> TransferFunction:
    """The transfer function of preset ``name`` fitted to the scene volume (``core.fitted_preset``: its display
    range)."""
    return fitted_preset(name, scene.volume)


class Controls:
    """Widgets bound to a viewer's scene; ``box`` is what the viewer shows."""

    def __init__(self, viewer):
        self.viewer = viewer
        self._syncing = False
        scene = viewer.scene
        self.preset = widgets.Dropdown(options=("custom",) + PRESETS, value="custom", description="preset")
        self.mode = widgets.Dropdown(options=MODES, value=scene.mode, description="mode")
        self.shading = widgets.Dropdown(options=SHADINGS, value=scene.shading.mode, description="shading")
        self.add_light = widgets.Button(description="light at camera", tooltip="a spot light at the eye")
        self.clear_lights = widgets.Button(description="no lights")
        self.crop = self._crop_sliders(scene.volume)
        self.preset.observe(self._on_preset, names="value")
        self.mode.observe(lambda ch: self._set(mode=ch["new"]), names="value")
        self.shading.observe(lambda ch: self._set(shading=Shading(mode=ch["new"])), names="value")
        self.add_light.on_click(self._on_add_light)
        self.clear_lights.on_click(lambda _b: self._set(lights=()))
        for s in self.crop:
            s.observe(self._on_crop, names="value")
        self.box = widgets.VBox([
            widgets.HBox([self.preset, self.mode, self.shading]),
            widgets.HBox([self.add_light, self.clear_lights]),
            widgets.HBox(list(self.crop)),
        ])

    @staticmethod
    def _crop_sliders(volume) -> tuple:
        if volume is None:
            return ()
        nz, ny, nx = volume.shape
        return tuple(widgets.IntRangeSlider(value=(0, n - 1), min=0, max=n - 1, description=f"crop {axis}",
                                            continuous_update=False)
                     for axis, n in (("x", nx), ("y", ny), ("z", nz)))

    def _set(self, **changes) -> None:
        if not self._syncing:
            self.viewer.scene = self.viewer.scene.with_(**changes)

    def _on_preset(self, change) -> None:
        if change["new"] != "custom":
            self._set(transfer=preset_transfer(self.viewer.scene, change["new"]))

    def _on_add_light(self, _button) -> None:
        scene = self.viewer.scene
        self._set(lights=scene.lights + (gestures.light_at_camera(self.viewer.camera),))

    def _on_crop(self, _change) -> None:
        box = tuple(float(v) for s in self.crop for v in s.value)
        full = all(s.value == (s.min, s.max) for s in self.crop)
        self._set(clipping=Clipping(crop=None if full else box, planes=self.viewer.scene.clipping.planes))

    def sync(self) -> None:
        """Show the viewer's current scene in the widgets without re-rendering."""
        scene = self.viewer.scene
        self._syncing = True
        try:
            self.mode.value = scene.mode
            self.shading.value = scene.shading.mode
            crop = scene.clipping.crop if scene.clipping.crop_space == "voxel" else None
            for n, s in enumerate(self.crop):
                s.value = (s.min, s.max) if crop is None else (int(round(crop[2 * n])), int(round(crop[2 * n + 1])))
        finally:
            self._syncing = False
