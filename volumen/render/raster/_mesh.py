"""Triangle meshes drawn by OpenGL: Phong (per pixel) or Gouraud (per vertex) shading, any lights,
and the distance along each view ray written into ``Image.depth`` so a mesh and a volume picture compose.
"""

from __future__ import annotations

import time
import weakref
from collections import OrderedDict
from dataclasses import asdict, dataclass
from typing import Literal, get_args

import numpy as np

from ._context import Target, get_context, gl_thread
from ._glcamera import projection_matrix, view_depth_range, view_matrix
from ._shaders import program
from ._uniforms import MAX_CLIP, light_rows, max_lights, set_camera, set_clipping, set_lighting, set_uniform

__all__ = ["MeshOptions", "render_mesh", "render_isosurface_mesh", "isosurface_mesh", "clear_mesh_cache"]

MeshShading = Literal["phong", "gouraud"]

_meshes: OrderedDict = OrderedDict()   # (volume id, data key, level, step) -> (volume weakref, Mesh)
_buffers: OrderedDict = OrderedDict()  # id(mesh) -> (mesh weakref, vbo, ibo)


@dataclass(frozen=True, kw_only=True)
class MeshOptions:
    """How meshes are drawn.

    Parameters
    ----------
    shading : {"phong", "gouraud"}
        Lighting per pixel from the interpolated vertex normal, or per vertex
        with the colours interpolated.
    step : int
        Marching-cubes step (voxels) when the mesh is made from a scene's volume.
    """

    shading: MeshShading = "phong"
    step: int = 1

    def __post_init__(self) -> None:
        if self.shading not in get_args(MeshShading):
            raise ValueError(f"MeshOptions.shading must be one of {get_args(MeshShading)}; got {self.shading!r}")
        if int(self.step) < 1:
            raise ValueError(f"MeshOptions.step must be >= 1, got {self.step}")

    def to_dict(self) -> dict:
        return asdict(self)


def isosurface_mesh(volume, level: float, step: int = 1):
    """The marching-cubes mesh of ``volume`` at ``level`` (data units), world mm; cached (last four)."""
    from ...surface import marching_cubes

    d = volume.data
    key = (id(volume), id(d), d.shape, float(level), int(step), np.asarray(volume.affine).tobytes())
    hit = _meshes.get(key)
    if hit is not None and hit[0]() is volume:
        _meshes.move_to_end(key)
        return hit[1]
    mesh = marching_cubes(volume, float(level), step=int(step), voxel_coordinates=False)
    _meshes[key] = (weakref.ref(volume), mesh)
    while len(_meshes) > 4:
        _meshes.popitem(last=False)
    return mesh


def _gpu_buffers(ctx, mesh):
    hit = _buffers.get(id(mesh))
    if hit is not None and hit[0]() is mesh:
        _buffers.move_to_end(id(mesh))
        return hit[1], hit[2]
    data = np.concatenate([mesh.vertices, mesh.normals], axis=1).astype(np.float32)
    vbo = ctx.buffer(data.tobytes())
    ibo = ctx.buffer(np.ascontiguousarray(mesh.faces, np.int32).tobytes())
    _buffers[id(mesh)] = (weakref.ref(mesh), vbo, ibo)
    while len(_buffers) > 4:
        _, old_vbo, old_ibo = _buffers.popitem(last=False)[1]
        old_vbo.release()
        old_ibo.release()
    return vbo, ibo


@gl_thread
def clear_mesh_cache() -> None:
    """Forget cached isosurface meshes and release their GPU buffers."""
    _meshes.clear()
    for _, vbo, ibo in _buffers.values():
        vbo.release()
        ibo.release()
    _buffers.clear()


def _program(ctx, lights: np.ndarray, opt: MeshOptions):
    """The mesh program compiled for the light count and Phong or Gouraud shading."""
    defines = {"MAX_LIGHTS": max_lights(len(lights)), "MAX_CLIP": MAX_CLIP}
    if opt.shading == "gouraud":
        defines["GOURAUD"] = ""
    return program(ctx, "mesh", defines)


def _near_far(mesh, camera) -> tuple[float, float]:
    """Near and far clip distances bracketing the mesh's bounding box (with a margin of 1e-3 of its depth)."""
    v = mesh.vertices if mesh.n_vertices else np.zeros((1, 3), np.float32)
    lo, hi = v.min(axis=0), v.max(axis=0)
    box = np.array([[hi[0] if b & 1 else lo[0], hi[1] if b & 2 else lo[1], hi[2] if b & 4 else lo[2]]
                    for b in range(8)], float)
    zmin, zmax = view_depth_range(camera, box)
    pad = 1e-3 * max(zmax - zmin, 1.0)
    if camera.projection == "orthographic":
        return zmin - pad, zmax + pad
    far = max(zmax, 1.0) + pad
    return max(zmin - pad, 1e-3 * far), far


def _set_uniforms(prog, mesh, camera, size, scene, color, lights: np.ndarray) -> None:
    """Camera, colour, clipping and lighting (unshaded: ambient 1, the flat colour)."""
    from ...core import Shading

    near, far = _near_far(mesh, camera)
    set_camera(prog, camera, projection_matrix(camera, size, near, far) @ view_matrix(camera))
    set_uniform(prog, "u_color", color)
    set_clipping(prog, camera, scene.clipping)
    shaded = scene.shading.mode != "none"
    shading = scene.shading if shaded else Shading(mode="none", ambient=1.0, diffuse=0.0, specular=0.0)
    set_lighting(prog, shading, lights)


def _draw(ctx, vao, mesh, size, timings: dict):
    """Draw with the depth test into fresh colour and distance targets; read back ``(rgba, depth)``
    (depth inf where nothing was drawn), adding ``draw`` and ``readback`` to ``timings``."""
    import moderngl

    target = Target(ctx, size, [(4, "f4"), (1, "f4")], depth=True)
    try:
        target.use()
        target.fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        ctx.disable(moderngl.BLEND | moderngl.CULL_FACE)
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.depth_func = "<"
        t = time.perf_counter()
        if mesh.n_faces:
            vao.render(moderngl.TRIANGLES)
        ctx.finish()
        timings["draw"] = time.perf_counter() - t
        t = time.perf_counter()
        rgba = target.read(0, 4)
        dist = target.read(1, 1)[..., 0]
        timings["readback"] = time.perf_counter() - t
    finally:
        target.release()
        ctx.disable(moderngl.DEPTH_TEST)
    return rgba, np.where(rgba[..., 3] > 0.5, dist, np.inf).astype(np.float32)


@gl_thread
def render_mesh(mesh, camera, size, *, scene=None, color=None, options: MeshOptions | None = None):
    """Draw a triangle mesh.

    Parameters
    ----------
    mesh : volumen.surface.Mesh
        ``vertices`` (N, 3) float32 world RAS+ mm, ``faces`` (M, 3) int,
        ``normals`` (N, 3) unit (either orientation: lighting is two-sided).
    camera : Camera
    size : (width, height), pixels
    scene : Scene, optional
        Supplies ``shading`` (``none``: flat colour, ``headlight``, ``phong``
        with ``lights``, any number; shadow, scattering and path-tracing modes
        light as ``phong``, without shadows) and ``clipping`` planes / world crop;
        default: headlight, no clipping.
    color : (3,) float, optional
        Linear RGB; default ``scene.isosurface.color``.
    options : MeshOptions, optional

    Returns
    -------
    Image
        ``rgba`` (H, W, 4) float32 (alpha 1 on the mesh, 0 elsewhere), row 0 at
        the top; ``depth`` (H, W) float32 mm along the view ray from the eye
        (orthographic: from the image plane through the camera position) to
        the nearest surface, inf where nothing was hit; ``stats``: ``timings``
        (``upload``, ``draw`` incl. ``glFinish``, ``readback``, ``total``),
        ``triangles``.
    """
    from ...core import Image, Scene, Shading

    t_start = time.perf_counter()
    opt = options or MeshOptions()
    scene = scene if scene is not None else Scene(shading=Shading(mode="headlight"))
    color = tuple(scene.isosurface.color if color is None else color)
    size = tuple(int(s) for s in size)
    ctx = get_context()
    lights = light_rows(scene, camera, scene.shading.mode != "none")
    prog = _program(ctx, lights, opt)
    t = time.perf_counter()
    vbo, ibo = _gpu_buffers(ctx, mesh)
    vao = ctx.vertex_array(prog, [(vbo, "3f 3f", "in_pos", "in_normal")], index_buffer=ibo, index_element_size=4)
    timings = {"upload": time.perf_counter() - t}
    try:
        _set_uniforms(prog, mesh, camera, size, scene, color, lights)
        rgba, depth = _draw(ctx, vao, mesh, size, timings)
    finally:
        vao.release()
    timings["total"] = time.perf_counter() - t_start
    stats = {"timings": timings, "options": opt.to_dict(), "triangles": mesh.n_faces,
             "gl_renderer": ctx.info.get("GL_RENDERER")}
    return Image(rgba=rgba, depth=depth, stats=stats)


@gl_thread
def render_isosurface_mesh(scene, camera, size, options: MeshOptions | None = None):
    """Technique ``mesh``: the isosurface of ``scene.volume`` at ``scene.isosurface.value`` by marching cubes
    (cached), drawn by :func:`render_mesh` in ``scene.isosurface.color``; ``stats["timings"]["mesh"]``
    is the extraction time (0 when cached)."""
    opt = options or MeshOptions()
    t = time.perf_counter()
    mesh = isosurface_mesh(scene.volume, scene.isosurface.value, opt.step)
    t_mesh = time.perf_counter() - t
    img = render_mesh(mesh, camera, size, scene=scene, options=opt)
    img.stats["timings"]["mesh"] = t_mesh
    img.stats["mode"] = "isosurface"
    return img
