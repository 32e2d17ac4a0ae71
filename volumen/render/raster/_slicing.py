"""Texture slicing: the volume as a 3-D texture cut by view-aligned planes, blended in order (OpenGL).

It computes the ray caster's integral (docs/design.md section 3) another way: each
plane polygon stands for the slab of view depth around it, its samples'
opacity corrected to the path a ray travels through that slab
(``gap / cos(theta)`` against the reference step ``ds0``), so orthographic
slicing and ray casting at the same samples per voxel agree.
"""

from __future__ import annotations

import time
from dataclasses import asdict, dataclass
from typing import Literal, NamedTuple, get_args

import numpy as np

from ._context import PRECISIONS, Target, get_context, gl_thread
from ._depth import DepthFromOpticalDepth
from ._glcamera import as_uniform, projection_matrix, view_depth_range, view_matrix
from ._planes import ADAPTIVE, Planes, box_corners, slab_boundaries, slice_polygons
from ._shaders import program
from ._textures import NLUT, classified_texture, tf_texture, value_range, value_texture
from ._uniforms import MAX_CLIP, light_rows, max_lights, set_camera, set_clipping, set_lighting, set_uniform

__all__ = ["SlicingOptions", "render_slicing"]

Order = Literal["back-to-front", "front-to-back"]
Precision = Literal["uint8", "float16", "float32"]
Classification = Literal["post", "pre"]


@dataclass(frozen=True, kw_only=True)
class SlicingOptions:
    """How texture slicing draws (settings as data; round-trips through ``asdict``/``SlicingOptions(**d)``).

    Parameters
    ----------
    order : {"back-to-front", "front-to-back"}
        Blending order: "over" from the back (``ONE, ONE_MINUS_SRC_ALPHA``) or
        "under" from the front (``ONE_MINUS_DST_ALPHA, ONE``).
    precision : {"uint8", "float16", "float32"}
        Format of the colour target the planes are blended into: 8-bit
        normalized (each blend rounds to 1/255: banding with many faint
        planes), 16-bit or 32-bit float.
    classification : {"post", "pre"}
        ``post``: interpolate values, then look up the transfer function;
        ``pre``: look up every voxel first, interpolate premultiplied colours.
    planes : one of ``volumen.render.raster.ADAPTIVE``
        Plane distribution along the view (see ``_planes``).
    depth : bool
        Fill ``Image.depth`` (where the accumulated opacity reaches 0.5, as the
        ray caster); costs a read-back of optical-depth moments every few planes.
    depth_chunk : int
        Planes between two read-backs (at least; at most 64 read-backs per frame).
    """

    order: Order = "back-to-front"
    precision: Precision = "float32"
    classification: Classification = "post"
    planes: Planes = "uniform"
    depth: bool = True
    depth_chunk: int = 8

    def __post_init__(self) -> None:
        for name, choices in (("order", get_args(Order)), ("precision", get_args(Precision)),
                              ("classification", get_args(Classification)), ("planes", ADAPTIVE)):
            if getattr(self, name) not in choices:
                raise ValueError(f"SlicingOptions.{name} must be one of {', '.join(map(repr, choices))}; "
                                 f"got {getattr(self, name)!r}")
        if int(self.depth_chunk) < 1:
            raise ValueError(f"SlicingOptions.depth_chunk must be >= 1, got {self.depth_chunk}")

    def to_dict(self) -> dict:
        return asdict(self)


def _box(volume, clipping):
    """Index-space box (lo, hi) of the drawn voxels: the voxel-centre box cut by a voxel crop."""
    nz, ny, nx = volume.shape
    lo, hi = np.zeros(3), np.array([nx - 1, ny - 1, nz - 1], float)
    if clipping.crop is not None and clipping.crop_space == "voxel":
        c = np.asarray(clipping.crop, float)
        lo, hi = np.maximum(lo, c[0::2]), np.minimum(hi, c[1::2])
    return lo, hi


def _world_to_tex(volume) -> np.ndarray:
    nz, ny, nx = volume.shape
    m = np.diag([1 / nx, 1 / ny, 1 / nz, 1.0])
    m[:3, 3] = 0.5 * np.array([1 / nx, 1 / ny, 1 / nz])
    return m @ np.linalg.inv(np.asarray(volume.affine, float))


class _Slabs(NamedTuple):
    """The planes of one frame: view-depth slabs and the polygons standing for them, in drawing order."""

    z0: float            #: first slab boundary (view depth, mm): the box's nearest point or the near plane
    zmax: float          #: farthest view depth of the box (mm)
    bounds: np.ndarray   #: slab boundaries, front to back
    back: bool           #: drawn back to front (polygons and ``gaps`` reversed)
    gaps: np.ndarray     #: slab thicknesses (mm), one per polygon, in drawing order
    attrs: np.ndarray    #: float32 (n, 4) vertex position (mm) and its slab's thickness
    tris: np.ndarray     #: int32 (m, 3) triangles
    first: np.ndarray    #: first triangle of each plane (and the total last)


def _slabs(scene, camera, opt: SlicingOptions, ds0: float) -> _Slabs:
    """Depth range, slab boundaries and the plane polygons (CPU, vectorised)."""
    volume = scene.volume
    corners = box_corners(*_box(volume, scene.clipping), volume.affine)
    zmin, zmax = view_depth_range(camera, corners)
    near = camera.near or 0.0
    z0 = max(zmin, near if camera.projection == "orthographic" else max(near, 1e-3 * ds0))
    bounds = slab_boundaries(opt.planes, z0, zmax, ds0=ds0, spv=scene.sampling.samples_per_voxel,
                             diagonal=volume.diagonal)
    depths, gaps = 0.5 * (bounds[1:] + bounds[:-1]), np.diff(bounds)
    back = opt.order == "back-to-front"
    if back:
        depths, gaps = depths[::-1], gaps[::-1]
    verts, tris, first = slice_polygons(corners, np.asarray(camera.position, float), camera.basis(), depths)
    attrs = np.concatenate([verts, np.repeat(gaps, 12)[:, None].astype(np.float32)], axis=1)
    return _Slabs(z0, zmax, bounds, back, gaps, attrs, tris, first)


def _program(ctx, scene, lights: np.ndarray, pre: bool):
    """The slicing program compiled for the light count, pre- or post-classification and shading."""
    defines = {"MAX_LIGHTS": max_lights(len(lights)), "MAX_CLIP": MAX_CLIP, "PROBE": "a" if pre else "r"}
    if pre:
        defines["PRE_CLASSIFIED"] = ""
    if scene.shading.mode != "none":
        defines["SHADED"] = ""
    return program(ctx, "slicing", defines)


def _textures(ctx, scene, pre: bool):
    """The volume texture (values, or classified colours for ``pre``) and the transfer-function texture."""
    volume = scene.volume
    vmin, vmax = value_range(volume)
    vol_tex = classified_texture(ctx, volume, scene.transfer) if pre else value_texture(ctx, volume)
    return vol_tex, tf_texture(ctx, scene.transfer, vmin, vmax)


def _set_uniforms(prog, scene, camera, size, slabs: _Slabs, lights: np.ndarray, ds0: float) -> None:
    """Camera, texture mapping, opacity-correction reference, clipping and lighting."""
    volume = scene.volume
    ortho = camera.projection == "orthographic"
    z0, far = slabs.z0, max(slabs.zmax, slabs.z0) + ds0
    proj = projection_matrix(camera, size, z0 - ds0 if ortho else 0.5 * z0, far)
    set_camera(prog, camera, proj @ view_matrix(camera))
    set_uniform(prog, "u_world_to_tex", as_uniform(_world_to_tex(volume)))
    set_uniform(prog, "u_tf_n", float(NLUT))
    set_uniform(prog, "u_ds0", ds0)
    set_uniform(prog, "u_zref", float(z0))
    set_uniform(prog, "u_jitter", bool(scene.sampling.jitter))
    set_uniform(prog, "u_seed", int(scene.sampling.seed))
    set_clipping(prog, camera, scene.clipping)
    nz, ny, nx = volume.shape
    set_uniform(prog, "u_texel", (1 / nx, 1 / ny, 1 / nz))
    set_uniform(prog, "u_grad_to_world", as_uniform(np.linalg.inv(volume.affine[:3, :3]).T))
    set_lighting(prog, scene.shading, lights)
    set_uniform(prog, "u_volume", 0)
    set_uniform(prog, "u_tf", 1)


def _blend(ctx, back: bool) -> None:
    """Premultiplied "over" from the back, or "under" from the front; no depth test, no culling."""
    import moderngl

    ctx.disable(moderngl.DEPTH_TEST | moderngl.CULL_FACE)
    ctx.enable(moderngl.BLEND)
    ctx.blend_equation = moderngl.FUNC_ADD
    ctx.blend_func = ((moderngl.ONE, moderngl.ONE_MINUS_SRC_ALPHA) if back
                      else (moderngl.ONE_MINUS_DST_ALPHA, moderngl.ONE))


def _draw_planes(vao, target, slabs: _Slabs, opt: SlicingOptions, camera, size):
    """Blend every plane into ``target``; with ``opt.depth`` in chunks, reading the optical-depth moments
    after each: returns the :class:`DepthFromOpticalDepth` tracker, or None."""
    import moderngl

    n, first = len(slabs.gaps), slabs.first
    if not (opt.depth and n):
        if len(slabs.tris):
            vao.render(moderngl.TRIANGLES)
        return None
    chunk = max(int(opt.depth_chunk), -(-n // 64))
    tracker = DepthFromOpticalDepth(camera, size, slabs.bounds, slabs.back)
    for p0 in range(0, n, chunk):
        p1 = min(p0 + chunk, n)
        if first[p1] > first[p0]:
            vao.render(moderngl.TRIANGLES, vertices=3 * int(first[p1] - first[p0]), first=3 * int(first[p0]))
        tracker.add(p1, target.read(attachment=1, components=3))
    return tracker


def _draw(ctx, vao, slabs: _Slabs, opt: SlicingOptions, camera, size, timings: dict):
    """Draw into a fresh target of ``opt.precision`` (plus a float moments target for depth); read back
    ``(rgba, depth)``, adding ``draw`` and ``readback`` to ``timings``."""
    import moderngl

    w, h = size
    colors = [(4, PRECISIONS[opt.precision])] + ([(4, "f4")] if opt.depth else [])
    target = Target(ctx, (w, h), colors)
    try:
        target.use()
        target.fbo.clear(0.0, 0.0, 0.0, 0.0)
        _blend(ctx, slabs.back)
        t = time.perf_counter()
        tracker = _draw_planes(vao, target, slabs, opt, camera, (w, h))
        ctx.finish()
        timings["draw"] = time.perf_counter() - t
        t = time.perf_counter()
        rgba = np.clip(target.read(0, 4), 0.0, 1.0)
        depth = tracker.depth() if tracker is not None else np.full((h, w), np.inf, np.float32)
        timings["readback"] = time.perf_counter() - t
    finally:
        target.release()
        ctx.disable(moderngl.BLEND)
    return rgba, depth


@gl_thread
def render_slicing(scene, camera, size, options: SlicingOptions | None = None):
    """Render ``scene`` (composite mode) by texture slicing into an Image of ``size = (width, height)``.

    Parameters
    ----------
    scene : Scene
        Its volume, transfer function, shading (``none``, ``headlight``,
        ``phong`` with the scene's lights; the shadow, scattering and path
        tracing modes are lit as ``phong``, without shadows), ``sampling.samples_per_voxel``
        (plane spacing ``ds0 / spv`` for the uniform distribution), clipping
        (voxel or world crop box, clip planes) and ``sampling.jitter`` (each pixel's samples moved along its
        ray by its share of the slab, ``sampling.seed``: no wood grain) are honoured;
        pre-integration, gradient opacity and early termination are not.
    camera : Camera
    size : (width, height), pixels
    options : SlicingOptions, optional

    Returns
    -------
    Image
        ``rgba`` (H, W, 4) float32 premultiplied, row 0 at the top; ``depth``
        (H, W) float32 mm along the view ray where the accumulated opacity
        first reaches 0.5 (inf where never, or all inf with
        ``options.depth=False``); ``stats``: ``timings`` (``geometry``,
        ``upload``, ``draw`` incl. ``glFinish``, ``readback``, ``total``,
        seconds), ``planes``, ``triangles``, ``plane_spacing_mm`` (min, max).
    """
    from ...core import Image

    opt = options or SlicingOptions()
    if scene.mode != "composite":
        raise ValueError(f"texture slicing renders mode 'composite' only; got {scene.mode!r}")
    t_start = time.perf_counter()
    size = tuple(int(s) for s in size)
    ctx = get_context()
    ds0 = float(min(scene.volume.spacing))
    slabs = _slabs(scene, camera, opt, ds0)
    timings: dict[str, float] = {"geometry": time.perf_counter() - t_start}

    t = time.perf_counter()
    pre = opt.classification == "pre"
    lights = light_rows(scene, camera, scene.shading.mode != "none")
    prog = _program(ctx, scene, lights, pre)
    vol_tex, tf_tex = _textures(ctx, scene, pre)
    vbo, ibo = ctx.buffer(slabs.attrs.tobytes()), ctx.buffer(slabs.tris.tobytes())
    vao = ctx.vertex_array(prog, [(vbo, "3f 1f", "in_pos", "in_gap")], index_buffer=ibo, index_element_size=4)
    timings["upload"] = time.perf_counter() - t
    try:
        _set_uniforms(prog, scene, camera, size, slabs, lights, ds0)
        vol_tex.use(0)
        tf_tex.use(1)
        rgba, depth = _draw(ctx, vao, slabs, opt, camera, size, timings)
    finally:
        for obj in (vao, vbo, ibo):
            obj.release()
    timings["total"] = time.perf_counter() - t_start
    gaps = slabs.gaps
    stats = {"timings": timings, "mode": "composite", "options": opt.to_dict(),
             "planes": int(len(gaps)), "triangles": int(len(slabs.tris)),
             "plane_spacing_mm": (float(gaps.min()), float(gaps.max())) if len(gaps) else (0.0, 0.0),
             "reference_step_mm": ds0, "gl_renderer": ctx.info.get("GL_RENDERER")}
    return Image(rgba=rgba, depth=depth, stats=stats)
