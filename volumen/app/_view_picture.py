"""One picture of the 3D view, from settings to 8-bit RGB, without Qt.

A :class:`FrameJob` is everything that decides the 3D view's picture (the
scene, the camera, the size, the technique, brightness, stereo, a mesh); the
render worker turns it into :class:`ViewPicture` objects with :func:`render_frame`
(at a reduced viewport while the user drags -- and, for a chunked OME-Zarr
volume, from a coarse pyramid level) or :func:`progressive_frames`
(the full picture; path tracing refines step by step). The same function
makes screenshots at any size, so what is saved is what is shown.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field, replace

import numpy as np

from ..core import Camera, Image, Scene, is_chunked
from ..render import Technique, resolve_device
from ._stereo import Stereo, combine, eye_cameras, eye_size

__all__ = ["FrameJob", "ViewPicture", "render_frame", "progressive_frames", "to_rgb", "composite_mesh", "on_gl_thread",
           "raycast_device", "needs_gl"]


@dataclass(frozen=True, kw_only=True)
class FrameJob:
    """What to draw.

    Parameters
    ----------
    scene : Scene
        With its volume attached.
    camera : Camera
    size : (width, height), pixels
    device : str
        One of ``volumen.render.DEVICES`` (resolved when the picture is drawn).
    technique : volumen.render.Technique
    brightness : float
        Gain on the rendered colour.
    background : (3,) float, linear RGB
    stereo : Stereo
    mesh : volumen.surface.Mesh or None
    mesh_display : {"hidden", "with-volume", "instead"}
    token : int
        Identifies the request (the newest picture wins).
    """

    scene: Scene
    camera: Camera
    size: tuple[int, int]
    device: str = "cpu"
    technique: Technique = field(default_factory=Technique)
    brightness: float = 1.0
    background: tuple[float, float, float] = (0.0, 0.0, 0.0)
    stereo: Stereo = field(default_factory=Stereo)
    mesh: object = None
    mesh_display: str = "hidden"
    token: int = 0


@dataclass
class ViewPicture:
    """A finished picture: ``rgb`` uint8 ``(H, W, 3)``, row 0 at the top.

    ``final`` is False for reduced-viewport frames and intermediate path-tracing
    steps; ``seconds`` the time the picture took; ``fraction`` the viewport
    fraction (1 = full size); ``spp`` path-traced samples per pixel (0 otherwise).
    """

    rgb: np.ndarray
    token: int
    final: bool
    seconds: float
    fraction: float = 1.0
    spp: int = 0
    camera: Camera | None = None
    stats: dict = field(default_factory=dict)


def to_rgb(image: Image, brightness: float = 1.0, background=(0.0, 0.0, 0.0)) -> np.ndarray:
    """``image`` (premultiplied linear RGBA) times ``brightness``, over ``background``: uint8 ``(H, W, 3)``.

    The conversion itself is :meth:`Image.to_uint8` (the one place pictures become 8-bit).
    """
    return image.to_uint8(tuple(float(c) for c in background), gain=brightness)


def composite_mesh(volume_image: Image, mesh_image: Image) -> Image:
    """The volume picture with an opaque mesh picture: the nearer one in front, per pixel.

    Where the mesh is nearer than the volume's depth (where its opacity reached
    0.5) the mesh shows; elsewhere the volume is composed over the mesh.
    """
    v, m = volume_image, mesh_image
    front = (m.rgba[..., 3] > 0) & (m.depth < v.depth)
    under = v.rgba + (1.0 - v.rgba[..., 3:4]) * m.rgba
    rgba = np.where(front[..., None], m.rgba, under).astype(np.float32)
    return Image(rgba=rgba, depth=np.minimum(v.depth, m.depth), stats=dict(v.stats))


def raycast_device(job: FrameJob) -> str:
    """The device that draws ``job``: its own, but the CPU for path tracing asked of ``gl`` (not done there)."""
    s = job.scene
    if (job.technique.name == "raycast" and resolve_device(job.device, "raycast") == "gl"
            and s.shading.mode == "pathtrace" and s.mode == "composite"):
        return "cpu"
    return job.device


def _render_one(job: FrameJob, camera: Camera, size, fraction: float, interacting: bool) -> Image:
    """One eye's picture; a chunked (OME-Zarr) volume is drawn out of core from a coarse pyramid level while
    ``interacting`` (``volumen.scale.render_view``)."""
    from ..render import render_reduced

    if job.mesh is not None and job.mesh_display == "instead":
        vol_img = None
    elif is_chunked(job.scene.volume.data):
        from ..scale import render_view

        vol_img = render_view(job.scene, camera, size, fraction, interacting=interacting)
    else:
        vol_img = render_reduced(job.scene, camera, size, fraction, device=raycast_device(job),
                                 technique=job.technique)
    if job.mesh is None or job.mesh_display == "hidden":
        return vol_img
    from ..render.raster import render_mesh

    mesh_img = render_mesh(job.mesh, camera, size, scene=job.scene)
    return mesh_img if vol_img is None else composite_mesh(vol_img, mesh_img)


def needs_gl(job: FrameJob) -> bool:
    """True when ``job`` draws with OpenGL (a rasterized technique, or a mesh)."""
    return (resolve_device(job.device, job.technique.name) == "gl"
            or (job.mesh is not None and job.mesh_display != "hidden"))


def on_gl_thread(fn, *args, **kw):
    """Run ``fn(*args, **kw)`` on the process's one OpenGL thread (``volumen.render.raster.on_gl_thread``).

    The headless OpenGL context is current in the thread that made it, so a whole
    frame that draws with OpenGL runs there, whichever window or task asks.
    """
    from ..render.raster import on_gl_thread as run

    return run(fn, *args, **kw)


def render_frame(job: FrameJob, fraction: float = 1.0, *, final: bool = True) -> ViewPicture:
    """Render ``job`` (each stereo eye) at ``fraction`` of its size, upscaled, combined: one :class:`ViewPicture`.

    OpenGL techniques run on the OpenGL thread (:func:`on_gl_thread`).
    """
    if needs_gl(job) and not threading.current_thread().name.startswith("volumen-gl"):
        return on_gl_thread(render_frame, job, fraction, final=final)
    t = time.perf_counter()
    cams = eye_cameras(job.camera, job.stereo)
    esize = eye_size(job.size, job.stereo)
    stats = {}
    pics = []
    for cam in cams:
        img = _render_one(job, cam, esize, fraction, interacting=not final)
        stats = img.stats
        pics.append(to_rgb(img, job.brightness, job.background))
    rgb = combine(pics, job.stereo, job.size)
    return ViewPicture(rgb=rgb, token=job.token, final=final, seconds=time.perf_counter() - t, fraction=fraction,
                 camera=job.camera, stats=stats)


def _progressive(job: FrameJob) -> bool:
    s = job.scene
    return (s.shading.mode == "pathtrace" and s.mode == "composite" and job.technique.name == "raycast"
            and resolve_device(raycast_device(job), "raycast") == "cpu"
            and job.stereo.mode == "off" and (job.mesh is None or job.mesh_display == "hidden"))


def progressive_frames(job: FrameJob, *, batch: int = 4,
                       cancelled: Callable[[], bool] = lambda: False) -> Iterator[ViewPicture]:
    """The full-size picture of ``job``; for path tracing, one :class:`ViewPicture` per ``batch`` samples per pixel.

    Path tracing (shading ``pathtrace``, composite mode, ray casting, mono)
    accumulates up to ``scene.shading.pathtrace.samples`` samples per pixel, yielding
    a refined frame after each batch and stopping early when ``cancelled()``
    turns true; the last frame has ``final=True``. Anything else is one final frame.
    """
    if not _progressive(job):
        yield render_frame(job, 1.0, final=True)
        return
    from ..render import PathTracer

    t = time.perf_counter()
    total = job.scene.shading.pathtrace.samples
    tracer = PathTracer(job.scene, job.camera, job.size)
    while tracer.spp < total:
        n = min(batch, total - tracer.spp)
        img = tracer.step(n)
        done = tracer.spp >= total
        yield ViewPicture(rgb=to_rgb(img, job.brightness, job.background), token=job.token, final=done,
                    seconds=time.perf_counter() - t, spp=tracer.spp, camera=job.camera, stats=img.stats)
        if not done and cancelled():
            return


def with_size(job: FrameJob, size: tuple[int, int]) -> FrameJob:
    """The same job at another size (screenshots)."""
    return replace(job, size=(int(size[0]), int(size[1])))
