"""The notebook widget: a jupyter-rfb canvas showing a :class:`View`, its controls and the slice views.

``Viewer`` is an ipywidgets box: the settings row (:mod:`._controls`), the 3-D canvas and, for a
volume, the linked axial / coronal / sagittal views (:mod:`._slices`). ``viewer.scene`` and
``viewer.camera`` read and set the picture; ``viewer.scene.to_json()`` and ``viewer.camera.to_json()``
are what ``volumen render --scene ... --camera ...`` reads.
"""

from __future__ import annotations

import asyncio
import base64

import ipywidgets as widgets
from jupyter_rfb import RemoteFrameBuffer

from ..core import Camera, Scene
from . import pictures
from ._view import View

__all__ = ["ViewCanvas", "Viewer"]


class ViewCanvas(RemoteFrameBuffer):
    """The remote frame buffer of a :class:`View`: browser events in, the view's newest frame out.

    Frames are rendered on the view's thread; when one is done the canvas asks jupyter-rfb to draw on
    the kernel's event loop, and :meth:`get_frame` hands over the newest frame not yet sent.
    """

    def __init__(self, view: View, **kw):
        w, h = view.size
        super().__init__(css_width=f"{w}px", css_height=f"{h}px", **kw)
        try:
            self._kernel_loop = asyncio.get_running_loop()
        except RuntimeError:
            self._kernel_loop = None
        self._unsent = None
        self.view = view
        view.on_frame = self._frame_done
        if view.frame is not None:
            self._frame_done(view.frame, view.final)

    def _frame_done(self, frame, final: bool) -> None:
        self._unsent = frame
        loop = self._kernel_loop
        if loop is not None and not loop.is_closed():
            loop.call_soon_threadsafe(self.request_draw)

    def get_frame(self):
        frame, self._unsent = self._unsent, None
        return frame

    def handle_event(self, event: dict) -> None:
        self.view.handle_event(event)


class Viewer(widgets.VBox):
    """``volumen.show``'s widget: controls, the 3-D canvas and the slice views.

    Attributes
    ----------
    view : View
        The scene, camera and render loop (``viewer.view.wait()`` blocks until the final frame).
    canvas : ViewCanvas
    controls : Controls
    slices : SliceViews or None
    """

    def __init__(self, scene: Scene, camera: Camera, size=(384, 384), slices: bool = True, **how):
        from ._controls import Controls
        from ._slices import SliceViews

        self.view = View(scene, camera, size, **how)
        self.canvas = ViewCanvas(self.view)
        self.controls = Controls(self)
        self.slices = SliceViews(scene.volume) if slices and scene.volume is not None else None
        children = [self.controls.box, self.canvas] + ([self.slices.box] if self.slices else [])
        super().__init__(children=children)

    @property
    def scene(self) -> Scene:
        return self.view.scene

    @scene.setter
    def scene(self, scene: Scene) -> None:
        self.view.scene = scene
        self.controls.sync()

    @property
    def camera(self) -> Camera:
        return self.view.camera

    @camera.setter
    def camera(self, camera: Camera) -> None:
        self.view.camera = camera

    @property
    def frame(self):
        """The newest frame, uint8 (H, W, 3), or None before the first."""
        return self.view.frame

    def wait(self, timeout: float = 60.0) -> bool:
        """Block until the final frame of the current scene and camera is rendered."""
        return self.view.wait(timeout)

    def _repr_mimebundle_(self, **kwargs):
        """The widget, plus its newest frame as ``image/png`` for pages without a widget manager (nbviewer,
        a saved notebook)."""
        data = super()._repr_mimebundle_(**kwargs)
        if isinstance(data, tuple):
            data = data[0]
        data = dict(data or {"text/plain": repr(self)})
        if self.frame is not None:
            data["image/png"] = base64.b64encode(pictures.png_bytes(self.frame)).decode()
        return data

    def snapshot_html(self) -> str:
        """A standalone HTML page with this widget's canvas showing the current frame (:func:`export_html`)."""
        from ._export import export_html

        self.wait()
        return export_html(self.frame)

    def close(self) -> None:
        self.view.close()
        super().close()
