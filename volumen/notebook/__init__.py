"""volumen in Jupyter: an interactive 3-D view with controls and linked slice views.

``volumen.show(volume_or_scene)`` returns a :class:`Viewer` (ipywidgets + jupyter-rfb): drag to orbit
(Shift or middle button: pan; right button or wheel: zoom) with the desktop application's gestures
(:mod:`volumen.core.gestures`); frames are rendered on a background thread, at a reduced viewport
while dragging and at full size once the mouse rests. ``viewer.scene`` and ``viewer.camera`` read and
set the picture. The jupyter packages are imported by :func:`show`, not by ``import volumen.notebook``.
Pictures (Image, Volume, Mesh) display themselves through :mod:`volumen.core.display`.
"""

from __future__ import annotations

from ._loop import REDUCED_FRACTION, REFINE_AFTER, RenderLoop
from ._view import View, ViewState, drag_kind, draw_frame

__all__ = ["show", "View", "ViewState", "RenderLoop", "draw_frame", "drag_kind", "export_html",
           "REDUCED_FRACTION", "REFINE_AFTER"]


def show(volume_or_scene, camera=None, *, size=(384, 384), slices: bool = True, preset: str | None = None, **how):
    """An interactive notebook view of a Volume or a Scene.

    Parameters
    ----------
    volume_or_scene : Volume or Scene
        A volume gets ``volumen.render.default_transfer`` (or ``preset``) and headlight shading.
    camera : Camera, optional
        Default: ``Camera.orbit(volume)`` (the anterior view).
    size : (width, height), pixels of the 3-D view
    slices : bool
        Show the linked axial / coronal / sagittal views with window and level.
    preset : str, optional
        A transfer-function preset name (``volumen.core.PRESETS``) for a volume.
    **how
        ``device``, ``technique`` and technique options for ``volumen.render.render``.

    Returns
    -------
    Viewer
        An ipywidgets box; ``.scene``, ``.camera`` (settable), ``.wait()``, ``.frame``, ``.snapshot_html()``.
    """
    from ..core import Camera, Scene, Volume
    from ._widget import Viewer

    if isinstance(volume_or_scene, Volume):
        from ..render import default_transfer

        vol = volume_or_scene
        tf = default_transfer(vol, "composite")
        scene = Scene(volume=vol, volume_ref=vol.name, transfer=tf)
        if preset is not None:
            from ._controls import preset_transfer

            scene = scene.with_(transfer=preset_transfer(scene, preset))
    elif isinstance(volume_or_scene, Scene):
        scene = volume_or_scene
    else:
        raise ValueError(f"show takes a Volume or a Scene, got {type(volume_or_scene).__name__}")
    if scene.volume is None:
        raise ValueError("the scene has no volume attached (Scene(volume=...))")
    return Viewer(scene, camera or Camera.orbit(scene.volume), size, slices=slices, **how)


def export_html(frame) -> str:
    """A standalone HTML page showing ``frame`` in jupyter-rfb's widget front end; see ``_export``."""
    from ._export import export_html as _export

    return _export(frame)
