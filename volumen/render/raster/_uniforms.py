"""Setting uniforms of the raster programs: lights, Phong coefficients, camera, clip planes."""

from __future__ import annotations

import numpy as np

from ._glcamera import as_uniform

__all__ = ["light_rows", "max_lights", "set_uniform", "set_lighting", "set_camera", "clip_rows",
           "set_clipping", "MAX_CLIP"]

#: clip planes a program can hold: 6 from a world crop box plus 6 scene planes
MAX_CLIP = 12


def light_rows(scene, camera, shaded: bool) -> np.ndarray:
    """float32 ``(n, 10)``: position (mm), unit spot direction, colour x intensity, spot exponent.

    The headlight is a white point light at the eye (as in the ray caster);
    the other shading modes use the scene's lights, resolved for ``camera``
    (head lights and lights attached to the camera; point lights shine every
    way); unshaded gives no rows.
    """
    if not shaded:
        return np.zeros((0, 10), np.float32)
    if scene.shading.mode == "headlight":
        _, _, f = camera.basis()
        return np.array([[*camera.position, *f, 1.0, 1.0, 1.0, 0.0]], np.float32)
    rows = []
    for lt in scene.lights:
        if hasattr(lt, "in_world"):
            pos, d = lt.in_world(camera)
            exponent = 0.0 if getattr(lt, "kind", None) == "point" else lt.exponent
        else:  # lights without kinds: world point or spot lights
            pos, d, exponent = lt.position, np.asarray(lt.direction) / np.linalg.norm(lt.direction), lt.exponent
        rows.append([*pos, *d, *(np.asarray(lt.color) * lt.intensity), exponent])
    return np.array(rows, np.float32).reshape(-1, 10)


def max_lights(n: int) -> int:
    """Array size compiled into a program for ``n`` lights: the next power of two (>= 1)."""
    return 1 << max(int(n) - 1, 0).bit_length()


def set_uniform(prog, name: str, value) -> None:
    """Set ``name`` if the program uses it (the compiler drops unused uniforms)."""
    try:
        u = prog[name]
    except KeyError:
        return
    if isinstance(value, bytes):
        u.write(value)
    else:
        u.value = value


def set_lighting(prog, shading, rows: np.ndarray) -> None:
    """Lights (``rows`` from :func:`light_rows`, padded to the program's array size) and Phong terms."""
    n = len(rows)
    cap = max_lights(n)
    pad = np.zeros((cap, 10), np.float32)
    pad[:n] = rows
    set_uniform(prog, "u_nlights", n)
    set_uniform(prog, "u_light_pos", pad[:, 0:3].tobytes())
    set_uniform(prog, "u_light_dir", pad[:, 3:6].tobytes())
    set_uniform(prog, "u_light_col", pad[:, 6:9].tobytes())
    set_uniform(prog, "u_light_exp", np.ascontiguousarray(pad[:, 9]).tobytes())
    set_uniform(prog, "u_phong", (shading.ambient, shading.diffuse, shading.specular, shading.shininess))


def set_camera(prog, camera, mvp: np.ndarray) -> None:
    """``u_mvp``, ``u_eye``, ``u_forward``, ``u_ortho``."""
    _, _, f = camera.basis()
    set_uniform(prog, "u_mvp", as_uniform(mvp))
    set_uniform(prog, "u_eye", tuple(float(x) for x in camera.position))
    set_uniform(prog, "u_forward", tuple(float(x) for x in f))
    set_uniform(prog, "u_ortho", camera.projection == "orthographic")


def clip_rows(clipping) -> np.ndarray:
    """float32 ``(n, 4)`` planes ``(n, w)`` keeping ``dot(n, p) + w >= 0``: the world crop box's faces
    (when ``crop_space == "world"``) and the scene's clip planes."""
    rows = []
    if clipping.crop is not None and clipping.crop_space == "world":
        c = clipping.crop
        for axis in range(3):
            e = np.eye(3)[axis]
            rows.append([*e, -c[2 * axis]])
            rows.append([*(-e), c[2 * axis + 1]])
    for p in clipping.planes:
        n = np.asarray(p.normal, float) / np.linalg.norm(p.normal)
        rows.append([*n, -float(n @ np.asarray(p.point, float))])
    return np.array(rows, np.float32).reshape(-1, 4)


def set_clipping(prog, camera, clipping) -> None:
    """``u_range`` (the camera's near and far distances; 0 and 3e38 when unset) and the clip planes
    ``u_nclip``, ``u_clip`` (the first :data:`MAX_CLIP` rows of :func:`clip_rows`, zero-padded)."""
    set_uniform(prog, "u_range", (camera.near or 0.0, camera.far if camera.far is not None else 3.0e38))
    rows = clip_rows(clipping)[:MAX_CLIP]
    pad = np.zeros((MAX_CLIP, 4), np.float32)
    pad[:len(rows)] = rows
    set_uniform(prog, "u_nclip", len(rows))
    set_uniform(prog, "u_clip", pad.tobytes())
