"""volumen in Jupyter: an interactive 3-D view with controls and linked slice views.

``volumen.show(volume_or_scene)`` returns a :class:`Viewer` (ipywidgets + jupyter-rfb): drag to orbit
(Shift or middle button: pan; right button or wheel: zoom) with the desktop application's gestures
(:mod:`volumen.core.gestures`); frames are rendered on a background thread, at a reduced viewport
while dragging and at full size once the mouse rests. ``viewer.scene`` and ``viewer.camera`` read and
set the picture. The jupyter packages are imported by :func:`show`, not by ``import volumen.notebook``.
Pictures (Image, Volume, Mesh) display themselves through :mod:`volumen.notebook.pictures`.
"""

from __future__ import annotations

from ._loop import REDUCED_FRACTION, REFINE_AFTER, RenderLoop
from ._view import View, ViewState, drag_kind, draw_frame

__all__ = ["show", "View", "ViewState", "RenderLoop", "draw_frame", "drag_kind", "export_html", "phantom_ref",
           "REDUCED_FRACTION", "REFINE_AFTER"]


def show(volume_or_scene, camera=None, *, size=(384, 384), slices: bool = True, preset: str | None = None,
         volume_ref: str = "", **how):
    """An interactive notebook view of a Volume or a Scene.

    Parameters
    ----------
    volume_or_scene : Volume or Scene
        A volume is drawn as ``volumen render`` draws it with no flags (``volumen.render.default_look``: a single
        slice's MIP, a colour slab opaque and unshaded), or with ``preset``.
    camera : Camera, optional
        Default: ``core.default_camera(volume)`` (the anterior view, fitted to the subject).
    size : (width, height), pixels of the 3-D view
    slices : bool
        Show the linked axial / coronal / sagittal views with window and level.
    preset : str, optional
        A transfer-function preset name (``volumen.core.PRESETS``) for a volume.
    volume_ref : str, optional
        Where the volume comes from (a path), written into ``viewer.scene.to_dict()`` so ``volumen render
        --settings`` can load it; default ``phantom:NAME?size=N`` for a built-in phantom, else empty.
    **how
        ``device``, ``technique`` and technique options for ``volumen.render.render``.

    Returns
    -------
    Viewer
        An ipywidgets box; ``.scene``, ``.camera`` (settable), ``.wait()``, ``.frame``, ``.snapshot_html()``.
    """
    from ..core import Scene, Volume, default_camera
    from ..errors import require

    for package in ("ipywidgets", "jupyter_rfb"):
        require(package, "volumen.show")
    from ._widget import Viewer

    if isinstance(volume_or_scene, Volume):
        from ..core import Isosurface, Shading, default_iso
        from ..render import default_look

        vol = volume_or_scene
        mode, tf, shaded = default_look(vol, transfer_named=preset is not None)
        scene = Scene(volume=vol, volume_ref=volume_ref or phantom_ref(vol), transfer=tf, mode=mode,
                      shading=Shading(mode=shaded), isosurface=Isosurface(value=default_iso(vol)))
        if preset is not None:
            from ._controls import preset_transfer

            scene = scene.with_(transfer=preset_transfer(scene, preset))
    elif isinstance(volume_or_scene, Scene):
        scene = volume_or_scene
    else:
        raise ValueError(f"show takes a Volume or a Scene, got {type(volume_or_scene).__name__}")
    if scene.volume is None:
        raise ValueError("the scene has no volume attached (Scene(volume=...))")
    return Viewer(scene, camera or default_camera(scene.volume), size, slices=slices, **how)


def phantom_ref(volume) -> str:
    """``phantom:NAME?size=N&param=value`` for a volume made by ``volumen.data.phantom`` (as the command line
    reads it), else ``""``."""
    from urllib.parse import urlencode

    made = volume.meta.get("phantom")
    if not made:
        return ""
    query = {k: v for k, v in {"size": made.get("size"), **made.get("params", {})}.items() if v is not None}
    return f"phantom:{made['name']}" + (f"?{urlencode(query)}" if query else "")


def export_html(frame) -> str:
    """A standalone HTML page showing ``frame`` in jupyter-rfb's widget front end; see ``_export``."""
    from ._export import export_html as _export

    return _export(frame)
