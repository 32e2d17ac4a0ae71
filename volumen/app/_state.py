"""The application's model: what is loaded and how it is shown, as plain Python (no Qt).

:class:`AppState` holds the volume, the :class:`~volumen.core.Scene` and
:class:`~volumen.core.Camera` that decide the 3D picture, and the state of the
slice views (crosshair, window), the segmentation and the display. Widgets
read it and change it through its methods; every change is announced to the
listeners of a *topic* (a plain observer list, so the model never imports Qt):

``volume``, ``scene``, ``camera``, ``crosshair``, ``window``, ``mask``,
``seeds``, ``mesh``, ``display``, ``selection``, ``crop``, ``endoscopy``, ``measurements``.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Callable
from dataclasses import replace

import numpy as np

from ..core import Camera, Scene, Window, canonical, default_camera, default_iso, default_window, is_color_slab
from ..measure import Measurements, check_scan
from ..render import Technique, resolve_device

__all__ = ["AppState", "TOPICS", "PICTURE_TOPICS", "MESH_DISPLAYS"]

TOPICS = ("volume", "scene", "camera", "crosshair", "window", "mask", "seeds", "mesh", "display", "selection",
          "crop", "endoscopy", "measurements")
#: topics whose change needs a new 3D picture
PICTURE_TOPICS = ("volume", "scene", "camera", "mesh", "display")
#: how an extracted mesh is shown in the 3D view
MESH_DISPLAYS = ("hidden", "with-volume", "instead")


class AppState:
    """Everything the views show, with change notification.

    Attributes
    ----------
    volume : Volume or None
        The data; ``canonical`` is it reoriented to RAS voxel order (slices).
    scene : Scene
        Transfer function, lights, mode, shading, sampling, clipping (its
        ``volume`` is :attr:`volume`).
    camera : Camera or None
    device : str
        Where the 3D view is rendered: one of ``volumen.render.DEVICES`` the technique runs on, or ``auto``.
    technique : volumen.render.Technique
        How the 3D view is rendered (``raycast``, ``slicing``, ``mesh``) with its options.
    brightness : float
        Display gain applied to the rendered colour (1 = as rendered).
    background : (3,) float
        Linear RGB behind the volume.
    stereo : Stereo
        Stereo output settings (``volumen.app._stereo``).
    crosshair : (3,) float, world RAS+ mm
        The point the three slice views go through.
    window : Window
        Level and width of the slice views (data units).
    mask : Volume or None
        Segmentation mask (uint8 0/1) on the volume's grid; ``mask_canonical`` reoriented.
    seeds : list of (3,) float, world mm
    measurements : volumen.measure.Measurements
        Rulers and regions placed on the slice views (world mm, on :attr:`volume`'s scan).
    mesh : volumen.surface.Mesh or None; ``mesh_display`` one of :data:`MESH_DISPLAYS`.
    selected_light : int or None
        Index into ``scene.lights``.
    interacting : bool
        True while the user drags in the 3D view (frames at a reduced viewport).
    """

    def __init__(self) -> None:
        from ._stereo import Stereo

        self.volume = None
        self.canonical = None
        self.scene = Scene()
        self.camera: Camera | None = None
        self.device = "cpu"
        self.technique = Technique()
        self.brightness = 1.0
        self.background = (0.0, 0.0, 0.0)
        self.stereo = Stereo()
        self.crosshair = np.zeros(3)
        self.window = Window(level=40.0, width=400.0)
        self.mask = None
        self.mask_canonical = None
        self.seeds: list[np.ndarray] = []
        self.measurements = Measurements()
        self.mesh = None
        self.mesh_display = "hidden"
        self.selected_light: int | None = None
        self.interacting = False
        self._listeners: dict[str, list[Callable[[], None]]] = defaultdict(list)
        self._muted = 0
        self._pending: set[str] = set()

    # -- observers ----------------------------------------------------------
    def subscribe(self, topic: str, callback: Callable[[], None]) -> None:
        """Call ``callback()`` after each change of ``topic`` (one of :data:`TOPICS`)."""
        if topic not in TOPICS:
            raise ValueError(f"unknown topic {topic!r}; valid: {', '.join(TOPICS)}")
        self._listeners[topic].append(callback)

    def emit(self, *topics: str) -> None:
        """Announce changes (batched while inside :meth:`batch`)."""
        if self._muted:
            self._pending.update(topics)
            return
        for t in topics:
            for cb in list(self._listeners[t]):
                cb()

    def batch(self):
        """Context manager: announce the changes made inside it once, at the end."""
        state = self

        class _Batch:
            def __enter__(self):
                state._muted += 1

            def __exit__(self, *exc):
                state._muted -= 1
                if not state._muted and state._pending:
                    topics = [t for t in TOPICS if t in state._pending]
                    state._pending.clear()
                    state.emit(*topics)

        return _Batch()

    # -- data ---------------------------------------------------------------
    def set_volume(self, volume, ref: str, *, transfer=None, camera: Camera | None = None) -> None:
        """Show a new volume: camera (``core.default_camera``: anterior, a slab face-on, fitted to the subject),
        crosshair and window reset; without a ``transfer`` (a session's) the compositing mode and transfer function
        too, as the command line picks them (``render.default_look``: a single slice's MIP), and the shading into
        and out of a colour slab (unshaded; the lighting chosen for other volumes carries over)."""
        from ..render import default_look

        with self.batch():
            leaving = self.volume is not None and is_color_slab(self.volume)
            self.volume = volume
            self.canonical = canonical(volume)
            shading = self.scene.shading  # the user's lighting carries over, except into and out of a colour slab
            iso = self.scene.isosurface
            if transfer is None:
                mode, tf, shaded = default_look(volume)
                iso = replace(iso, value=default_iso(volume))
                if leaving or is_color_slab(volume):
                    shading = replace(shading, mode=shaded)
            else:  # a session's look
                mode, tf = self.scene.mode, transfer
            self.scene = replace(self.scene, volume=volume, volume_ref=ref, transfer=tf, mode=mode, shading=shading,
                                 isosurface=iso, clipping=replace(self.scene.clipping, crop=None))
            self.camera = camera if camera is not None else default_camera(volume)
            self.crosshair = np.asarray(volume.center, float)
            self.window = default_window(volume)
            self.mask = self.mask_canonical = None
            self.seeds = []
            self.measurements = Measurements()
            self.mesh = None
            self.selected_light = None
            self.emit("volume", "scene", "camera", "crosshair", "window", "mask", "seeds", "mesh", "selection",
                      "crop", "measurements")

    # -- scene and camera ---------------------------------------------------
    def update_scene(self, **changes) -> None:
        """Replace fields of the scene (``transfer=...``, ``lights=...``, ``shading=...``...)."""
        self.scene = replace(self.scene, **changes)
        self.emit("scene")
        if "clipping" in changes:
            self.emit("crop")

    def set_camera(self, camera: Camera) -> None:
        self.camera = camera
        self.emit("camera")

    def set_display(self, **changes) -> None:
        """Change ``device``, ``technique``, ``brightness``, ``background``, ``stereo`` or ``mesh_display``.

        A technique given without a device keeps the device when the technique runs on it, else takes the
        technique's default device."""
        if "technique" in changes and "device" not in changes:
            tech = changes["technique"]
            if self.device not in (*tech.spec.devices, "auto"):
                changes["device"] = resolve_device(None, tech.name)
        for k, v in changes.items():
            if k not in ("device", "technique", "brightness", "background", "stereo", "mesh_display"):
                raise ValueError(f"unknown display setting {k!r}")
            if k == "mesh_display" and v not in MESH_DISPLAYS:
                raise ValueError(f"mesh_display must be one of {MESH_DISPLAYS}, got {v!r}")
            setattr(self, k, v)
        self.emit("display")

    # -- lights -------------------------------------------------------------
    def set_lights(self, lights, selected: int | None = -1) -> None:
        """Replace the lights; ``selected`` -1 keeps the selection (clamped to the new list)."""
        lights = tuple(lights)
        self.scene = replace(self.scene, lights=lights)
        if selected != -1:
            self.selected_light = selected
        if self.selected_light is not None and self.selected_light >= len(lights):
            self.selected_light = len(lights) - 1 if lights else None
        self.emit("scene", "selection")

    def replace_light(self, index: int, light) -> None:
        lights = list(self.scene.lights)
        lights[index] = light
        self.set_lights(lights)

    def select_light(self, index: int | None) -> None:
        self.selected_light = index
        self.emit("selection")

    # -- slices -------------------------------------------------------------
    def set_crosshair(self, world) -> None:
        """Move the crosshair (world mm), clamped to the volume's box."""
        p = np.asarray(world, float).reshape(3)
        if self.volume is not None:
            lo, hi = self.volume.bounds()
            p = np.clip(p, lo, hi)
        self.crosshair = p
        self.emit("crosshair")

    def set_window(self, window: Window) -> None:
        self.window = window
        self.emit("window")

    # -- segmentation -------------------------------------------------------
    def set_mask(self, mask) -> None:
        self.mask = mask
        self.mask_canonical = None if mask is None else canonical(mask)
        self.emit("mask")

    def add_seed(self, world) -> None:
        self.seeds.append(np.asarray(world, float).reshape(3))
        self.emit("seeds")

    def clear_seeds(self) -> None:
        self.seeds = []
        self.emit("seeds")

    def set_measurements(self, items) -> None:
        """Replace the measurements (a session's); each must have been made on :attr:`volume`'s scan.

        Raises
        ------
        volumen.errors.MeasurementError
            A measurement of another scan (nothing is changed).
        """
        items = Measurements(items)
        check_scan(items, self.volume)
        self.measurements = items
        self.emit("measurements")

    def put_measurement(self, index: int | None, m) -> int:
        """Replace measurement ``index`` by ``m`` (``None``: add it); returns its index."""
        if index is None:
            self.measurements.append(m)
            index = len(self.measurements) - 1
        else:
            self.measurements[index] = m
        self.emit("measurements")
        return index

    def remove_measurement(self, index: int) -> None:
        del self.measurements[index]
        self.emit("measurements")

    def set_mesh(self, mesh, display: str | None = None) -> None:
        self.mesh = mesh
        if display is not None:
            self.mesh_display = display
        self.emit("mesh")
