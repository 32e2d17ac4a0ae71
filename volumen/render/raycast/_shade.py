"""Lighting of one sample, per shading model (light tag, :mod:`._pieces`), over the packed lights.

Lights are packed as float64 ``(n, 11)`` rows: position (world mm), unit spot
direction, colour x intensity (linear RGB), spot exponent (0 for point lights),
radius (mm, area-like lights of the path tracer). Head lights and lights
attached to the camera are resolved to world space when packed, so the
headlight goes through exactly the same code as scene lights.

Models (the ``shade`` piece of each light tag):

* ``Unlit``: factors (1, 1, 1, 0, 0, 0), the colour unchanged.
* ``Phong``: Phong, every light fully visible.
* ``Headlight``: Phong with the one light at the eye of a perspective camera, whose direction at a sample
  is the view direction ``v`` (the ray starts at the eye): the same light without a light vector per sample.
* ``Shadowed``: Phong with each light weighted by its visibility
  (:func:`light_visibility`).
* ``Scatter``: single scattering (:mod:`._scatter`): the sample's colour is
  scaled by ``albedo * (ambient + diffuse * sum_l 4 pi p_HG E_l T_l)``; no normals.

The ambient term is the environment's (``Settings.env_mode``, :mod:`._environment`): the uniform radiance
``ambient`` (``env_mode`` 0), or the environment map's irradiance over pi about the facing normal (Phong) and its
radiance weighted by the phase function toward the eye (``Scatter``), from its spherical harmonics.

The lit colour is ``c * f + s`` (straight colour), or ``C * f + alpha * s``
premultiplied. Phong: where the gradient is zero every light counts as
head-on (diffuse 1, no specular); normals are two-sided (face the viewer).
"""

from __future__ import annotations

import math

import numpy as np

from ...core import FACING, Light
from ...jit import njit
from ..optics import phong_terms, power, spot_factor
from ._environment import sh_irradiance, sh_phase
from ._geometry import to_index
from ._lightvol import DIRECT, LATTICE, LV_KIND, NEAR_STEPS, NO_SITE, lattice_ahead, lattice_read, lattice_site
from ._medium import frame_medium
from ._pieces import Headlight, Phong, Scatter, Shadowed, Unlit, piece, shade, uses_normals
from ._scatter import phase_weight
from ._shadow import shadow_transmittance

__all__ = ["pack_lights", "headlight", "light_vector", "light_visibility", "NLCOL"]

L_POS, L_DIR, L_COL, L_EXP, L_RAD = 0, 3, 6, 9, 10
NLCOL = 11


def pack_lights(lights, camera) -> np.ndarray:
    """float64 ``(max(n, 1), NLCOL)`` rows for :class:`~volumen.core.Light` objects seen by ``camera``."""
    rows = []
    for lt in lights:
        pos, d = lt.in_world(camera)
        exp = 0.0 if lt.kind == "point" else lt.exponent
        rows.append([*pos, *d, *(np.asarray(lt.color) * lt.intensity), exp, lt.radius])
    return np.array(rows if rows else [[0.0] * NLCOL], np.float64)


def headlight(camera) -> np.ndarray:
    """The headlight as one packed row: a white point light of intensity 1 at the eye, pointing along the view."""
    return pack_lights([_HEADLIGHT], camera)


_HEADLIGHT = Light(kind="headlight")


@njit(cache=True, fastmath=True, inline="always")
def light_vector(lights, li, wx, wy, wz):
    """``(lx, ly, lz, distance mm, spot factor)``: unit vector from world point w toward light ``li``."""
    lx = lights[li, L_POS] - wx
    ly = lights[li, L_POS + 1] - wy
    lz = lights[li, L_POS + 2] - wz
    d = math.sqrt(lx * lx + ly * ly + lz * lz)
    if d > 0.0:
        lx /= d
        ly /= d
        lz /= d
    spot = spot_factor(-lx, -ly, -lz, lights[li, L_DIR], lights[li, L_DIR + 1], lights[li, L_DIR + 2],
                       lights[li, L_EXP])
    return lx, ly, lz, d, spot


@njit(cache=True, fastmath=True)
def light_visibility(li, w, lv, dist, a, s):
    """Fraction of light ``li`` reaching the world point ``w`` (unit ``lv`` toward the light, ``dist`` mm away).

    The transmittance from ``w + offset lv`` to the light (docs/design.md section 3):
    read from the light's illumination volume (``LATTICE``, the first
    ``NEAR_STEPS`` reference steps marched) or marched (``DIRECT``, :mod:`._shadow`).
    """
    off = s.shadow_offset
    if dist <= off:
        return 1.0
    lx, ly, lz = lv
    yx = w[0] + off * lx
    yy = w[1] + off * ly
    yz = w[2] + off * lz
    kind = a.light_meta[li, LV_KIND]
    if kind != DIRECT and kind != LATTICE:
        return 1.0
    span = dist - off
    near = span if kind == DIRECT else min(NEAR_STEPS * s.ds0, span)  # marched; the lattice's beyond
    beyond = kind == LATTICE and near < span
    site = NO_SITE
    if beyond:  # where the lattice will be read, asked for before the near march
        xi, yi, zi = to_index(a.geo, yx + near * lx, yy + near * ly, yz + near * lz, 1.0)
        site = lattice_site(a.light_meta, li, xi, yi, zi)
        lattice_ahead(a.light_data, site)
    tr = shadow_transmittance(frame_medium(a, s), a.cells, s.cells, (a.geo, a.planes, s.nplanes), (yx, yy, yz),
                              (lx, ly, lz), near, (s.shadow_step, s.ds0, s.extinction_scale))
    if beyond and tr > 0.0:
        tr *= lattice_read(a.light_data, site)
    return tr


@njit(cache=True, fastmath=True, inline="always")
def _unit_facing(n, v):
    """``(nx, ny, nz, flat)``: the unit normal turned toward the viewer ``v`` (one at right angles to it, up to
    ``core.FACING``, keeps its side); flat where the gradient vanishes."""
    gx, gy, gz = n
    gl = math.sqrt(gx * gx + gy * gy + gz * gz)
    if gl < 1e-3:
        return 0.0, 0.0, 0.0, True
    nx = gx / gl
    ny = gy / gl
    nz = gz / gl
    if nx * v[0] + ny * v[1] + nz * v[2] < -FACING:
        return -nx, -ny, -nz, False
    return nx, ny, nz, False


#: fraction of light ``li`` reaching the world point ``w``, per light tag: a piece, so a kernel of the unshadowed
#: model does not even compile the shadow rays
visibility = piece("visibility", "li, w, lv, dist, a, s", "-> fraction of light li reaching w")


@visibility.register(Phong)
@njit(cache=True, fastmath=True, inline="always")
def _visible(li, w, lv, dist, a, s):
    return 1.0


@visibility.register(Shadowed)
@njit(cache=True, fastmath=True, inline="always")
def _visible_shadowed(li, w, lv, dist, a, s):
    return light_visibility(li, w, lv, dist, a, s)


@njit(cache=True, fastmath=True, inline="always")
def _ambient(a, s, nx, ny, nz):
    """The Phong models' ambient term: ``s.ambient`` (uniform environment) or the environment's irradiance / pi
    about the unit normal n ((0, 0, 0) where the gradient vanishes: the mean radiance)."""
    if s.env_mode == 0:
        return s.ambient, s.ambient, s.ambient
    return sh_irradiance(a, nx, ny, nz)


@njit(cache=True, fastmath=True, inline="always")
def _phong(light, a, s, n, v, w):
    """Phong over the lights, each weighted by its :data:`visibility` under the light tag."""
    nx, ny, nz, flat = _unit_facing(n, v)
    fr, fg, fb = _ambient(a, s, nx, ny, nz)
    sr = sg = sb = 0.0
    for li in range(s.nlights):
        lx, ly, lz, dist, spot = light_vector(a.lights, li, w[0], w[1], w[2])
        if spot <= 0.0:
            continue
        diff, spec = 1.0, 0.0
        if not flat:
            diff, spec = phong_terms((nx, ny, nz), (lx, ly, lz), v, s.shininess)
        if diff <= 0.0:
            continue
        wt = spot * visibility(light, li, w, (lx, ly, lz), dist, a, s)
        cr = wt * a.lights[li, L_COL]
        cg = wt * a.lights[li, L_COL + 1]
        cb = wt * a.lights[li, L_COL + 2]
        fr += s.diffuse * diff * cr
        fg += s.diffuse * diff * cg
        fb += s.diffuse * diff * cb
        sr += s.specular * spec * cr
        sg += s.specular * spec * cg
        sb += s.specular * spec * cb
    return fr, fg, fb, sr, sg, sb


@njit(cache=True, fastmath=True, inline="always")
def _headlight_terms(n, v, shine):
    """Diffuse and specular factors of a light at the eye, from the gradient ``n`` (not normalized) and the unit
    vector ``v`` toward the viewer: ``|N.V|`` and ``max(2 (N.V)^2 - 1, 0) ** shine`` (``R.V`` with ``L = V``),
    the values of :func:`phong_terms` for the normal turned toward the viewer, without forming that normal (a
    fifth of a translucent frame's time less); ``(1, 0)`` where the gradient vanishes, as there."""
    gx, gy, gz = n
    g2 = gx * gx + gy * gy + gz * gz
    if g2 < 1e-6:  # |g| < 1e-3: flat (``_unit_facing``)
        return 1.0, 0.0
    diff = abs(gx * v[0] + gy * v[1] + gz * v[2]) / math.sqrt(g2)
    rdv = 2.0 * diff * diff - 1.0
    return diff, (power(rdv, shine) if rdv > 0.0 else 0.0)


@shade.register(Unlit)
@njit(cache=True, fastmath=True, inline="always")
def _shade_unlit(a, s, n, v, w):
    return 1.0, 1.0, 1.0, 0.0, 0.0, 0.0


@shade.register(Phong)
@njit(cache=True, fastmath=True, inline="always")
def _shade_phong(a, s, n, v, w):
    return _phong(Phong(), a, s, n, v, w)


@shade.register(Headlight)
@njit(cache=True, fastmath=True, inline="always")
def _shade_headlight(a, s, n, v, w):
    diff, spec = _headlight_terms(n, v, s.shininess)
    kd = s.diffuse * diff
    ks = s.specular * spec
    cr, cg, cb = a.lights[0, L_COL], a.lights[0, L_COL + 1], a.lights[0, L_COL + 2]
    ar = ag = ab = s.ambient
    if s.env_mode != 0:  # the environment's irradiance about the unit normal
        nx, ny, nz, _ = _unit_facing(n, v)
        ar, ag, ab = _ambient(a, s, nx, ny, nz)
    return ar + kd * cr, ag + kd * cg, ab + kd * cb, ks * cr, ks * cg, ks * cb


@shade.register(Shadowed)
@njit(cache=True, fastmath=True, inline="always")
def _shade_shadowed(a, s, n, v, w):
    return _phong(Shadowed(), a, s, n, v, w)


@shade.register(Scatter)
@njit(cache=True, fastmath=True, inline="always")
def _shade_scatter(a, s, n, v, w):
    fr = fg = fb = s.ambient if s.env_mode == 0 else 0.0
    for li in range(s.nlights):
        lx, ly, lz, dist, spot = light_vector(a.lights, li, w[0], w[1], w[2])
        if spot <= 0.0:
            continue
        wt = spot * phase_weight(lx, ly, lz, v[0], v[1], v[2], s.phase_g)
        wt *= light_visibility(li, w, (lx, ly, lz), dist, a, s)
        fr += wt * a.lights[li, L_COL]
        fg += wt * a.lights[li, L_COL + 1]
        fb += wt * a.lights[li, L_COL + 2]
    kd, alb = s.diffuse, s.albedo
    if s.env_mode == 0:
        ka = s.ambient
        return (ka + kd * (fr - ka)) * alb, (ka + kd * (fg - ka)) * alb, (ka + kd * (fb - ka)) * alb, 0.0, 0.0, 0.0
    er, eg, eb = sh_phase(a, -v[0], -v[1], -v[2], s.phase_g)
    return (er + kd * fr) * alb, (eg + kd * fg) * alb, (eb + kd * fb) * alb, 0.0, 0.0, 0.0


@uses_normals.register(Phong, Headlight, Shadowed)
@njit(cache=True, inline="always")
def _normals_yes():
    return True


@uses_normals.register(Unlit, Scatter)
@njit(cache=True, inline="always")
def _normals_no():
    return False
