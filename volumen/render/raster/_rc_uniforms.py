"""The ray-casting shader's variant and uniforms for one packed frame, as plain values (no OpenGL here).

:func:`variant` gives the ``#define`` s of ``shaders/raycast.glsl`` (mode, lighting model, array sizes) and
:func:`frame_uniforms` every uniform but the texture units and the texture-layout ones (``u_vol_map``,
``u_light_data_w``, ``u_origin``): python numbers and tuples, and float32 / int32 arrays already in the order a
``glUniform*v`` call takes (matrices column-major). The OpenGL device sets them with moderngl
(``_raycast.py``); the browser viewer (``volumen.web``) sends the same dict to its page, which sets them with
WebGL2, so both draw from the values packed here once.
"""

from __future__ import annotations

import numpy as np

from ...core import FACING

__all__ = ["MAX_LIGHTS", "MAX_PLANES", "MODES", "LIGHTS", "variant", "frame_uniforms", "CAMERA_UNIFORMS",
           "LIGHT_UNIFORMS"]

#: most lights and clip planes one pass takes
MAX_LIGHTS = 16
MAX_PLANES = 16
#: mode tag (``raycast._pieces``) -> MODE of raycast.glsl; the projection tag's ``Settings.projection`` is added to it
MODES = {"Composite": 0, "Preintegrated": 1, "Projection": 2, "Isosurface": 5}
#: lighting tag -> LIGHT of raycast.glsl
LIGHTS = {"Unlit": 0, "Phong": 1, "Headlight": 1, "Shadowed": 2, "Scatter": 3}
#: uniforms of the packed camera (``raycast._geometry.pack_camera``): what a viewer changes per frame
CAMERA_UNIFORMS = ("u_eye", "u_right", "u_up", "u_fwd", "u_ortho", "u_half", "u_wh", "u_near", "u_far")
#: uniforms of the packed lights (``raycast._shade.pack_lights``)
LIGHT_UNIFORMS = ("u_nlights", "u_lpos", "u_ldir", "u_lcol", "u_lexp")


def variant(frame) -> dict:
    """The ``#define`` s of the frame's program: ``{"MODE": int, "LIGHT": int, "MAX_LIGHTS": .., "MAX_PLANES": ..,
    "FACING": float}`` (``core.FACING``)."""
    tag = type(frame.mode).__name__
    mode = MODES[tag] + (frame.settings.projection if tag == "Projection" else 0)
    return {"MODE": mode, "LIGHT": LIGHTS[type(frame.light).__name__],
            "MAX_LIGHTS": MAX_LIGHTS, "MAX_PLANES": MAX_PLANES, "FACING": repr(float(FACING))}


def _vec3s(rows: np.ndarray, cap: int) -> np.ndarray:
    out = np.zeros((cap, 3), np.float32)
    out[:len(rows)] = rows
    return out


def _geometry(a) -> dict:
    # the packed layouts (the raycast package loads Numba: with the frame, not at import)
    from ..raycast._geometry import (
        C_EYE,
        C_FAR,
        C_FWD,
        C_H,
        C_HALF,
        C_NEAR,
        C_ORTHO,
        C_RIGHT,
        C_UP,
        C_W,
        G_BOX,
        G_INV,
        G_WORLD,
        P_NORMAL,
        P_POINT,
    )

    cam, geo = a.cam, a.geo
    u = {name: tuple(float(v) for v in cam[i:i + 3])
         for name, i in (("u_eye", C_EYE), ("u_right", C_RIGHT), ("u_up", C_UP), ("u_fwd", C_FWD))}
    u.update(u_ortho=bool(cam[C_ORTHO] > 0.5), u_half=float(cam[C_HALF]), u_wh=(float(cam[C_W]), float(cam[C_H])),
             u_near=float(cam[C_NEAR]), u_far=float(min(cam[C_FAR], 1e30)))
    m = np.eye(4)
    m[:3, :4] = geo[G_INV:G_INV + 12].reshape(3, 4)
    u["u_to_index"] = np.ascontiguousarray(m.T, np.float32)  # column-major
    u["u_nmat"] = np.ascontiguousarray(a.gradient_matrix[:3].T, np.float32)
    for name, i in (("u_box_lo", G_BOX), ("u_box_hi", G_BOX + 3), ("u_wlo", G_WORLD), ("u_whi", G_WORLD + 3)):
        u[name] = tuple(float(v) for v in geo[i:i + 3])
    u["u_pp"] = _vec3s(a.planes[:, P_POINT:P_POINT + 3], MAX_PLANES)
    u["u_pn"] = _vec3s(a.planes[:, P_NORMAL:P_NORMAL + 3], MAX_PLANES)
    return u


def _lights(a, s) -> dict:
    from ..raycast._params import LV_OFF  # the packed layouts (as in _geometry)
    from ..raycast._shade import L_COL, L_DIR, L_EXP, L_POS

    n = s.nlights
    li = a.lights[:n]
    exp = np.zeros(MAX_LIGHTS, np.float32)
    exp[:n] = li[:, L_EXP]
    lvm = np.zeros((MAX_LIGHTS, 16), np.float32)
    off = np.zeros(MAX_LIGHTS, np.int32)
    m = min(len(a.light_meta), MAX_LIGHTS)
    lvm[:m] = a.light_meta[:m]
    off[:m] = a.light_meta[:m, LV_OFF]   # exact as an integer past float32's 2**24
    return {"u_nlights": int(n), "u_lpos": _vec3s(li[:, L_POS:L_POS + 3], MAX_LIGHTS),
            "u_ldir": _vec3s(li[:, L_DIR:L_DIR + 3], MAX_LIGHTS), "u_lcol": _vec3s(li[:, L_COL:L_COL + 3], MAX_LIGHTS),
            "u_lexp": exp, "u_lvm": lvm, "u_lvoff": off,
            "u_envsh": _vec3s(a.env_sh, 9)}   # the environment's ambient: 9 spherical-harmonic RGB coefficients


def _settings(s) -> dict:
    from ..raycast._pieces import BSpline  # the raycast package (Numba) loads with the frame, not at import

    scalars = ("ds", "ds0", "early_termination", "ambient", "diffuse", "specular", "shininess", "iso_value",
               "pre_scale", "shadow_offset", "shadow_step", "extinction_scale", "albedo", "phase_g")
    u = {f"u_{name}": float(getattr(s, name)) for name in scalars}
    u["u_iso_rgb"] = (float(s.iso_red), float(s.iso_green), float(s.iso_blue))
    flags = ("nearest", "jitter", "skip", "gradient_opacity", "sobel", "color", "hdr")
    u.update({f"u_{name}": bool(getattr(s, name)) for name in flags})
    u.update(u_seed=int(s.seed), u_block=int(s.block), u_nplanes=int(s.nplanes), u_env_mode=int(s.env_mode))
    u["u_recon"] = int(isinstance(s.recon, BSpline))  # the reconstruction tag (raycast._pieces)
    return u


def frame_uniforms(frame) -> dict:
    """Every uniform of the frame's program but the texture units, ``u_vol_map``, ``u_light_data_w`` and
    ``u_origin``."""
    a, s = frame.arrays, frame.settings
    u = {**_geometry(a), **_lights(a, s), **_settings(s)}
    u["u_inv_gmax"] = float(a.gradient_matrix[3, 0] / s.sample_scale)  # table units
    return u
