"""Lighting of one sample: the per-light loop over packed lights, for every shading model.

Lights are packed as float64 ``(n, 11)`` rows: position (world mm), unit spot
direction, colour x intensity (linear RGB), spot exponent (0 for point lights),
radius (mm, area-like lights of the path tracer). Head lights and lights
attached to the camera are resolved to world space when packed, so the
headlight goes through exactly the same code as scene lights.

Models (``iprm[I_MODEL]``):

* ``M_PHONG``: Phong, every light fully visible.
* ``M_SHADOWS``: Phong with each light weighted by its visibility
  (:func:`light_visibility`).
* ``M_SCATTER``: single scattering (:mod:`._scatter`): the sample's colour is
  scaled by ``albedo * (ambient + diffuse * sum_l 4 pi p_HG E_l T_l)``; no normals.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..optics import phong_terms, spot_factor
from ._geometry import to_index
from ._lightvol import DIRECT, LATTICE, LV_KIND, NEAR_STEPS, lattice_transmittance
from ._params import (
    I_MODEL,
    I_NLIGHTS,
    I_NPLANES,
    M_PHONG,
    M_SCATTER,
    P_ALBEDO,
    P_DS0,
    P_G,
    P_KA,
    P_KD,
    P_KEXT,
    P_KS,
    P_SH_OFF,
    P_SH_STEP,
    P_SHINE,
)
from ._scatter import phase_weight
from ._shadow import shadow_transmittance

__all__ = ["pack_lights", "headlight", "light_vector", "light_visibility", "shade", "NLCOL"]

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
    from ...core import Light

    return pack_lights([Light(kind="headlight")], camera)


@njit(cache=True, fastmath=True, inline="always")
def light_vector(lights, l, wx, wy, wz):
    """``(lx, ly, lz, distance mm, spot factor)``: unit vector from world point w toward light ``l``."""
    lx = lights[l, L_POS] - wx
    ly = lights[l, L_POS + 1] - wy
    lz = lights[l, L_POS + 2] - wz
    d = math.sqrt(lx * lx + ly * ly + lz * lz)
    if d > 0.0:
        lx /= d
        ly /= d
        lz /= d
    spot = spot_factor(-lx, -ly, -lz, lights[l, L_DIR], lights[l, L_DIR + 1], lights[l, L_DIR + 2],
                       lights[l, L_EXP])
    return lx, ly, lz, d, spot


@njit(cache=True, fastmath=True)
def light_visibility(l, wx, wy, wz, lx, ly, lz, dist, vol, geo, planes, lvm, lvd, sig, prm, iprm):
    """Fraction of light ``l`` reaching the world point w (unit ``L`` toward the light, ``dist`` mm away).

    1 in the Phong model. Otherwise the transmittance from ``w + offset L``
    to the light (DESIGN.md section 3): read from the light's illumination
    volume (``LATTICE``) or marched (``DIRECT``, :mod:`._shadow`).
    """
    if iprm[I_MODEL] == M_PHONG:
        return 1.0
    off = prm[P_SH_OFF]
    if dist <= off:
        return 1.0
    yx = wx + off * lx
    yy = wy + off * ly
    yz = wz + off * lz
    kind = lvm[l, LV_KIND]
    if kind == DIRECT:
        return shadow_transmittance(vol, sig, geo, planes, iprm[I_NPLANES], yx, yy, yz, lx, ly, lz, dist - off,
                                    prm[P_SH_STEP], prm[P_DS0], prm[P_KEXT])
    if kind == LATTICE:
        # the first NEAR_STEPS reference steps marched, the rest read from the light's volume
        near = min(NEAR_STEPS * prm[P_DS0], dist - off)
        tr = shadow_transmittance(vol, sig, geo, planes, iprm[I_NPLANES], yx, yy, yz, lx, ly, lz, near,
                                  prm[P_SH_STEP], prm[P_DS0], prm[P_KEXT])
        if near < dist - off and tr > 0.0:
            xi, yi, zi = to_index(geo, yx + near * lx, yy + near * ly, yz + near * lz, 1.0)
            tr *= lattice_transmittance(lvm, lvd, l, xi, yi, zi)
        return tr
    return 1.0


@njit(cache=True, fastmath=True)
def shade(gx, gy, gz, vx, vy, vz, wx, wy, wz, vol, geo, planes, lights, lvm, lvd, sig, prm, iprm):
    """Lighting factors of a sample.

    Parameters
    ----------
    gx, gy, gz : world gradient direction (any length; zero = flat region; unused by M_SCATTER)
    vx, vy, vz : unit vector from the sample toward the viewer
    wx, wy, wz : sample position, world mm
    vol, geo, planes : normalized volume and packed region (for shadow rays)
    lights : packed lights (``pack_lights``)
    lvm, lvd, sig : illumination-volume meta rows and buffer, optical depth table (``_lightvol``)
    prm, iprm : packed parameters (``_params``)

    Returns
    -------
    (fr, fg, fb, sr, sg, sb) : the lit colour is ``c * f + s`` (straight
    colour), or ``C * f + alpha * s`` premultiplied. Phong: where the gradient
    is zero every light counts as head-on (diffuse 1, no specular).
    """
    model = iprm[I_MODEL]
    nlights = iprm[I_NLIGHTS]
    ka = prm[P_KA]
    fr = ka
    fg = ka
    fb = ka
    sr = 0.0
    sg = 0.0
    sb = 0.0
    if model == M_SCATTER:
        g = prm[P_G]
        for l in range(nlights):
            lx, ly, lz, dist, spot = light_vector(lights, l, wx, wy, wz)
            if spot <= 0.0:
                continue
            w = spot * phase_weight(lx, ly, lz, vx, vy, vz, g)
            w *= light_visibility(l, wx, wy, wz, lx, ly, lz, dist, vol, geo, planes, lvm, lvd, sig, prm, iprm)
            fr += w * lights[l, L_COL]
            fg += w * lights[l, L_COL + 1]
            fb += w * lights[l, L_COL + 2]
        alb = prm[P_ALBEDO]
        kd = prm[P_KD]
        return (ka + kd * (fr - ka)) * alb, (ka + kd * (fg - ka)) * alb, (ka + kd * (fb - ka)) * alb, 0.0, 0.0, 0.0
    kd = prm[P_KD]
    ks = prm[P_KS]
    shininess = prm[P_SHINE]
    gl = math.sqrt(gx * gx + gy * gy + gz * gz)
    flat = gl < 1e-3
    nx = 0.0
    ny = 0.0
    nz = 0.0
    if not flat:
        nx = gx / gl
        ny = gy / gl
        nz = gz / gl
        if nx * vx + ny * vy + nz * vz < 0.0:  # two-sided: face the viewer
            nx = -nx
            ny = -ny
            nz = -nz
    for l in range(nlights):
        lx, ly, lz, dist, spot = light_vector(lights, l, wx, wy, wz)
        if spot <= 0.0:
            continue
        if flat:
            diff = 1.0
            spec = 0.0
        else:
            diff, spec = phong_terms(nx, ny, nz, lx, ly, lz, vx, vy, vz, shininess)
        if diff <= 0.0:
            continue
        w = spot
        if model != M_PHONG:  # Phong: every light reaches every sample (no call: its arrays cost refcounts)
            w *= light_visibility(l, wx, wy, wz, lx, ly, lz, dist, vol, geo, planes, lvm, lvd, sig, prm, iprm)
        wr = w * lights[l, L_COL]
        wg = w * lights[l, L_COL + 1]
        wb = w * lights[l, L_COL + 2]
        fr += kd * diff * wr
        fg += kd * diff * wg
        fb += kd * diff * wb
        sr += ks * spec * wr
        sg += ks * spec * wg
        sb += ks * spec * wb
    return fr, fg, fb, sr, sg, sb
