"""Ray casting on OpenGL: the CPU's packed frame marched by a fragment shader (``shaders/raycast.glsl``).

:func:`render_raycast_gl` packs the frame with the ray caster's own
``pack_frame`` (tables, normals, block grids, illumination volumes: built once
by the shared Python/Numba code), uploads it (:mod:`._rc_textures`), sets the
settings as uniforms and draws one full-screen triangle into two float32
targets: premultiplied RGBA, and (depth, value, samples). The shader is the
marching skeleton with the same pieces as the CPU kernels, compiled per
(mode, lighting model) through ``#define`` s, so the picture equals the CPU's
to float32 rounding and texture filtering.

Limits: at most :data:`MAX_LIGHTS` lights and :data:`MAX_PLANES` clip planes
per pass; a volume past the context's 3-D texture size raises
:class:`~volumen.errors.DeviceLimitError` (use the CPU device); path tracing
is not done on ``gl`` (:class:`~volumen.errors.DeviceLimitError` too).
"""

from __future__ import annotations

import time

import numpy as np

from ...errors import DeviceLimitError
from ._context import Target, get_context, gl_thread
from ._rc_textures import FrameTextures, check_limits
from ._rc_uniforms import MAX_LIGHTS, MAX_PLANES, frame_uniforms, variant
from ._shaders import program
from ._uniforms import set_uniform

__all__ = ["render_raycast_gl", "check_scene", "MAX_LIGHTS", "MAX_PLANES"]

_quad: dict = {}


def check_scene(scene) -> None:
    """Raise the :class:`DeviceLimitError` the gl ray caster gives ``scene`` before drawing (its limits)."""
    if scene.shading.mode == "pathtrace" and scene.mode == "composite":
        raise DeviceLimitError("path tracing runs on the cpu and cuda devices, not gl; use --device cpu")
    if getattr(scene, "labels", None) is not None and scene.mode == "composite":
        raise DeviceLimitError("label maps are drawn by the cpu and cuda devices, not gl; use --device cpu")
    if len(scene.lights) > MAX_LIGHTS and scene.shading.mode not in ("none", "headlight"):
        raise DeviceLimitError(f"{len(scene.lights)} lights: the gl ray caster takes at most {MAX_LIGHTS} per "
                               "pass; use --device cpu")
    if len(scene.clipping.planes) > MAX_PLANES:
        raise DeviceLimitError(f"{len(scene.clipping.planes)} clip planes: the gl ray caster takes at most "
                               f"{MAX_PLANES}; use --device cpu")


def _draw(ctx, prog, size):
    if id(ctx) not in _quad:
        _quad[id(ctx)] = ctx.buffer(np.array([-1, -1, 3, -1, -1, 3], np.float32).tobytes())
    vao = ctx.vertex_array(prog, [(_quad[id(ctx)], "2f", "in_pos")])
    with Target(ctx, size, [(4, "f4"), (4, "f4")]) as target:
        target.use()
        ctx.disable(ctx.BLEND | ctx.DEPTH_TEST)
        vao.render(vertices=3)
        rgba, aux = target.read(0, 4), target.read(1, 4)
    vao.release()
    return rgba, aux


@gl_thread
def render_raycast_gl(scene, camera, size: tuple[int, int]):
    """Ray-cast ``scene`` seen by ``camera`` on OpenGL into an Image of ``size = (width, height)``; see
    ``volumen.render.render``. Raises :class:`~volumen.errors.DeviceLimitError` for what the device cannot
    do (path tracing, a volume past the 3-D texture size, too many lights or planes)."""
    from ..raycast import FAR, Outputs, frame_image, pack_frame

    check_scene(scene)
    ctx = get_context()
    check_limits(ctx, scene.volume.shape)
    t_start = time.perf_counter()
    f = pack_frame(scene, camera, size)
    t = time.perf_counter()
    prog = program(ctx, "raycast", variant(f))
    tex = FrameTextures(ctx, f.arrays, f.settings, f.prep)
    try:
        for name, unit in tex.units.items():
            set_uniform(prog, f"u_{name}", unit)
        set_uniform(prog, "u_light_data_w", tex.width)
        set_uniform(prog, "u_vol_map", (0.0, 1.0))  # the R32F volume holds table units
        set_uniform(prog, "u_origin", (0.0, 0.0))
        for name, value in frame_uniforms(f).items():
            set_uniform(prog, name, value.tobytes() if isinstance(value, np.ndarray) else value)
        t_up = time.perf_counter()
        rgba, aux = _draw(ctx, prog, f.size)
    finally:
        tex.release()
    s = f.settings
    value, depth = aux[..., 1].copy(), aux[..., 0].copy()
    hit = value < 0.5 * FAR
    value[hit] = s.value_min + value[hit] * s.value_scale
    value[~hit] = np.nan
    depth[depth >= 0.5 * FAR] = np.inf
    out = Outputs(rgba, depth, value, np.rint(aux[..., 2]).astype(np.int32))
    now = time.perf_counter()
    timings = dict(f.timings, upload=t_up - t, kernel=now - t_up, total=now - t_start)
    return frame_image(scene, f, out, timings, {"backend": "gl"})
