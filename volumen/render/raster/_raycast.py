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
from ._shaders import program
from ._uniforms import set_uniform

__all__ = ["render_raycast_gl", "MAX_LIGHTS", "MAX_PLANES"]

#: most lights and clip planes one pass takes
MAX_LIGHTS = 16
MAX_PLANES = 16
_MODES = {"Composite": 0, "Preintegrated": 1, "Mip": 2, "Minip": 3, "Average": 4, "Isosurface": 5}
_LIGHTS = {"Unlit": 0, "Phong": 1, "Headlight": 1, "Shadowed": 2, "Scatter": 3}
_quad: dict = {}


def _check(scene) -> None:
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


def _vec3s(rows: np.ndarray, cap: int) -> bytes:
    out = np.zeros((cap, 3), np.float32)
    out[:len(rows)] = rows
    return out.tobytes()


def _set_geometry(prog, a) -> None:
    cam, geo = a.cam, a.geo
    for name, i in (("u_eye", 0), ("u_right", 3), ("u_up", 6), ("u_fwd", 9)):
        set_uniform(prog, name, tuple(float(v) for v in cam[i:i + 3]))
    set_uniform(prog, "u_ortho", bool(cam[12] > 0.5))
    set_uniform(prog, "u_half", float(cam[13]))
    set_uniform(prog, "u_wh", (float(cam[14]), float(cam[15])))
    set_uniform(prog, "u_near", float(cam[16]))
    set_uniform(prog, "u_far", float(min(cam[17], 1e30)))
    m = np.eye(4)
    m[:3, :4] = geo[:12].reshape(3, 4)
    set_uniform(prog, "u_to_index", m.T.astype(np.float32).tobytes())  # column-major
    set_uniform(prog, "u_nmat", np.ascontiguousarray(a.nrm[:3].T, np.float32).tobytes())
    for name, i in (("u_box_lo", 12), ("u_box_hi", 15), ("u_wlo", 18), ("u_whi", 21)):
        set_uniform(prog, name, tuple(float(v) for v in geo[i:i + 3]))
    set_uniform(prog, "u_pp", _vec3s(a.planes[:, :3], MAX_PLANES))
    set_uniform(prog, "u_pn", _vec3s(a.planes[:, 3:6], MAX_PLANES))


def _set_lights(prog, a, s) -> None:
    n = s.nlights
    li = a.lights[:n]
    set_uniform(prog, "u_nlights", int(n))
    set_uniform(prog, "u_lpos", _vec3s(li[:, 0:3], MAX_LIGHTS))
    set_uniform(prog, "u_ldir", _vec3s(li[:, 3:6], MAX_LIGHTS))
    set_uniform(prog, "u_lcol", _vec3s(li[:, 6:9], MAX_LIGHTS))
    exp = np.zeros(MAX_LIGHTS, np.float32)
    exp[:n] = li[:, 9]
    set_uniform(prog, "u_lexp", exp.tobytes())
    lvm = np.zeros((MAX_LIGHTS, 16), np.float32)
    off = np.zeros(MAX_LIGHTS, np.int32)
    m = min(len(a.lvm), MAX_LIGHTS)
    lvm[:m] = a.lvm[:m]
    off[:m] = a.lvm[:m, 1]   # LV_OFF, exact as an integer past float32's 2**24
    set_uniform(prog, "u_lvm", lvm.tobytes())
    set_uniform(prog, "u_lvoff", off.tobytes())
    set_uniform(prog, "u_envsh", _vec3s(a.envsh, 9))


def _set_settings(prog, s) -> None:
    for name in ("ds", "ds0", "et", "ka", "kd", "ks", "shine", "iso", "pre_scale", "sh_off", "sh_step", "kext",
                 "albedo", "g"):
        set_uniform(prog, f"u_{name}", float(getattr(s, name)))
    set_uniform(prog, "u_iso_rgb", (float(s.iso_r), float(s.iso_g), float(s.iso_b)))
    for name in ("nearest", "jitter", "skip", "gradop", "sobel", "color", "hdr"):
        set_uniform(prog, f"u_{name}", bool(getattr(s, name)))
    set_uniform(prog, "u_envmode", int(s.envmode))
    set_uniform(prog, "u_seed", int(s.seed))
    set_uniform(prog, "u_block", int(s.block))


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

    _check(scene)
    ctx = get_context()
    check_limits(ctx, scene.volume.shape)
    t_start = time.perf_counter()
    f = pack_frame(scene, camera, size)
    t = time.perf_counter()
    prog = program(ctx, "raycast", {"MODE": _MODES[type(f.mode).__name__], "LIGHT": _LIGHTS[type(f.light).__name__],
                                    "MAX_LIGHTS": MAX_LIGHTS, "MAX_PLANES": MAX_PLANES})
    tex = FrameTextures(ctx, f.arrays, f.settings, f.prep)
    try:
        for name, unit in tex.units.items():
            set_uniform(prog, f"u_{name}", unit)
        set_uniform(prog, "u_lvd_w", tex.width)
        set_uniform(prog, "u_nplanes", int(f.settings.nplanes))
        _set_geometry(prog, f.arrays)
        _set_lights(prog, f.arrays, f.settings)
        _set_settings(prog, f.settings)
        set_uniform(prog, "u_inv_gmax", float(f.arrays.nrm[3, 0] / f.settings.ufac))  # table units
        t_up = time.perf_counter()
        rgba, aux = _draw(ctx, prog, f.size)
    finally:
        tex.release()
    s = f.settings
    value, depth = aux[..., 1].copy(), aux[..., 0].copy()
    hit = value < 0.5 * FAR
    value[hit] = s.vmin + value[hit] * s.vscale
    value[~hit] = np.nan
    depth[depth >= 0.5 * FAR] = np.inf
    out = Outputs(rgba, depth, value, np.rint(aux[..., 2]).astype(np.int32))
    now = time.perf_counter()
    timings = dict(f.timings, upload=t_up - t, kernel=now - t_up, total=now - t_start)
    return frame_image(scene, f, out, timings, {"backend": "gl"})
