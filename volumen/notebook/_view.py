"""The 3-D view of the notebook without Jupyter: scene, camera, mouse events and frames.

Events are the dicts jupyter-rfb delivers (``type`` ``pointer_down`` / ``pointer_move`` /
``pointer_up`` / ``wheel`` / ``resize``, with ``x``, ``y`` in CSS pixels, ``button`` 1 left, 2 right,
3 middle, ``modifiers`` such as ``("Shift",)``, ``dx``, ``dy`` for the wheel). The gestures are the
desktop application's (:mod:`volumen.core.gestures`): left drag orbits, Shift+left or middle drag
pans, right drag zooms (:func:`~volumen.core.gestures.drag_zoom`), a wheel notch (100 units in browsers)
zooms as a notch does in the app (:func:`~volumen.core.gestures.wheel_zoom`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from ..core import Camera, Scene, gestures, is_chunked
from ..render import _standin, render_reduced
from ._loop import REDUCED_FRACTION, RenderLoop

__all__ = ["View", "ViewState", "draw_frame", "stand_in_frame", "drag_kind"]

#: wheel units per notch in browsers (the app's Qt wheel counts 120 per notch)
WHEEL_NOTCH = 100.0


@dataclass(frozen=True)
class ViewState:
    """Everything one frame depends on: scene, camera, size (width, height) and how to render."""

    scene: Scene
    camera: Camera
    size: tuple[int, int]
    how: tuple = ()  # (("device", ...), ("technique", ...), options...) for volumen.render.render


def draw_frame(state: ViewState, fraction: float = 1.0) -> np.ndarray:
    """uint8 ``(H, W, 3)`` picture of ``state``: ``volumen.render`` (at ``fraction`` of the size, upscaled); a
    chunked (OME-Zarr) volume out of core, from a coarse pyramid level while reduced (``fraction < 1``: the
    user drags), see ``volumen.scale.render_view``."""
    if not is_chunked(state.scene.volume.data):
        return render_reduced(state.scene, state.camera, state.size, fraction, **dict(state.how)).to_uint8()
    from ..scale import render_view

    return render_view(state.scene, state.camera, state.size, fraction, interacting=fraction < 1.0).to_uint8()


def stand_in_frame(state: ViewState, fraction: float = 1.0):
    """``(frame, fraction, compiled)`` while the CPU kernel of ``state``'s picture compiles aside: OpenGL's stand-in
    (uint8, at most ``volumen.render._standin.FRACTION`` of the size, upscaled), the fraction it was drawn at and
    the Event set once the kernel is compiled; None when the picture should be drawn now (:func:`draw_frame`)."""
    how = dict(state.how)
    compiled = _standin.compiling(state.scene, state.camera, how.get("device"), how.get("technique"))
    if compiled is None:
        return None
    try:
        img = _standin.draw(state.scene, state.camera, state.size, fraction)
    except Exception:  # noqa: BLE001 - no stand-in: draw_frame then draws on the CPU, compiling
        return None
    return img.to_uint8(), _standin.drawn_at(fraction), compiled


def drag_kind(button: int, modifiers) -> str | None:
    """``"orbit"``, ``"pan"`` or ``"zoom"`` for a pointer press (jupyter-rfb button numbers), as in the app."""
    if button == 1:
        return "pan" if "Shift" in tuple(modifiers or ()) else "orbit"
    return {3: "pan", 2: "zoom"}.get(button)


class View:
    """Scene and camera of one 3-D view, the mouse gestures on them, and its background render loop.

    Parameters
    ----------
    scene : Scene
    camera : Camera
    size : (width, height), pixels
    on_frame : callable(frame uint8 (H, W, 3), final: bool), optional
        Called on the render thread with each finished frame.
    **how
        ``device``, ``technique`` and technique options for ``volumen.render.render``.
    """

    def __init__(self, scene: Scene, camera: Camera, size=(384, 384), on_frame: Callable | None = None, **how):
        self._state = ViewState(scene, camera, (int(size[0]), int(size[1])), tuple(how.items()))
        self.on_frame = on_frame
        self.frame: np.ndarray | None = None
        self.frame_state: ViewState | None = None
        self.final = False
        self._drag: tuple | None = None
        self._loop = RenderLoop(draw_frame, self._deliver, stand_in=stand_in_frame)
        self.redraw()

    # -- state -------------------------------------------------------------------------------
    @property
    def state(self) -> ViewState:
        return self._state

    @property
    def scene(self) -> Scene:
        return self._state.scene

    @scene.setter
    def scene(self, scene: Scene) -> None:
        if not isinstance(scene, Scene):
            raise ValueError(f"scene must be a Scene, got {type(scene).__name__}")
        self._set(scene=scene)

    @property
    def camera(self) -> Camera:
        return self._state.camera

    @camera.setter
    def camera(self, camera: Camera) -> None:
        if not isinstance(camera, Camera):
            raise ValueError(f"camera must be a Camera, got {type(camera).__name__}")
        self._set(camera=camera)

    @property
    def size(self) -> tuple[int, int]:
        return self._state.size

    def _set(self, fraction: float = 1.0, **changes) -> None:
        self._state = replace(self._state, **changes)
        self.redraw(fraction)

    def redraw(self, fraction: float = 1.0) -> int:
        """Ask the render thread for a picture of the current state (returns at once)."""
        return self._loop.request(self._state, fraction)

    def wait(self, timeout: float = 60.0) -> bool:
        """Block until the final frame of the current state is done (scripts and tests)."""
        return self._loop.wait(timeout)

    def close(self) -> None:
        self._loop.close()

    def _deliver(self, frame: np.ndarray, request) -> None:
        self.frame, self.frame_state, self.final = frame, request.state, request.fraction >= 1.0
        if self.on_frame is not None:
            self.on_frame(frame, self.final)

    # -- events --------------------------------------------------------------------------------
    def handle_event(self, event: dict) -> None:
        """Apply one jupyter-rfb event (see the module docstring)."""
        kind = event.get("type", event.get("event_type"))
        if kind == "resize":
            size = (max(1, int(round(event["width"]))), max(1, int(round(event["height"]))))
            if size != self.size:
                self._set(size=size)
        elif kind == "pointer_down":
            drag = drag_kind(event.get("button", 0), event.get("modifiers", ()))
            self._drag = None if drag is None else (drag, event["x"], event["y"])
        elif kind == "pointer_move" and self._drag is not None:
            drag, x0, y0 = self._drag
            dx, dy = event["x"] - x0, event["y"] - y0
            self._drag = (drag, event["x"], event["y"])
            self._set(REDUCED_FRACTION, camera=self._dragged(drag, dx, dy))
        elif kind == "pointer_up" and self._drag is not None:
            self._drag = None
            self.redraw()
        elif kind == "wheel":
            steps = -float(event.get("dy", 0.0)) / WHEEL_NOTCH
            if steps:
                self._set(REDUCED_FRACTION, camera=gestures.wheel_zoom(self.camera, steps))

    def _dragged(self, drag: str, dx: float, dy: float) -> Camera:
        if drag == "orbit":
            return gestures.orbit(self.camera, dx, dy)
        if drag == "pan":
            return gestures.pan(self.camera, dx, dy, self.size)
        return gestures.drag_zoom(self.camera, dy)
