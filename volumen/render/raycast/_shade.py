"""Lighting of one sample: the per-light loop over packed lights, using the Phong terms of optics.

Lights are packed as float64 ``(n, 10)`` rows: position (world mm), unit spot
direction, colour x intensity (linear RGB), spot exponent. The headlight is
packed as one such row (a point light at the eye), so it goes through exactly
the same code as scene lights.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..optics import phong_terms, spot_factor

__all__ = ["pack_lights", "light_visibility", "shade"]

L_POS, L_DIR, L_COL, L_EXP = 0, 3, 6, 9


def pack_lights(lights) -> np.ndarray:
    """float64 ``(max(n, 1), 10)`` rows for :class:`~volumen.core.Light` objects."""
    rows = [[*lt.position, *(np.asarray(lt.direction) / np.linalg.norm(lt.direction)),
             *(np.asarray(lt.color) * lt.intensity), lt.exponent] for lt in lights]
    return np.array(rows if rows else [[0.0] * 10], np.float64)


def headlight(camera) -> np.ndarray:
    """The headlight as one packed row: a white point light of intensity 1 at the eye, pointing along the view."""
    _, _, f = camera.basis()
    return np.array([[*camera.position, *f, 1.0, 1.0, 1.0, 0.0]], np.float64)


@njit(cache=True, fastmath=True)
def light_visibility(vol, lights, l, x, y, z, wx, wy, wz):
    """Fraction of light ``l`` reaching the sample at index (x, y, z) / world (wx, wy, wz).

    1 for now; shadows (DESIGN.md section 3) plug in here.
    """
    return 1.0


@njit(cache=True, fastmath=True)
def shade(gx, gy, gz, vx, vy, vz, wx, wy, wz, x, y, z, vol, lights, nlights, ka, kd, ks, shininess):
    """Phong factors of a sample.

    Parameters
    ----------
    gx, gy, gz : world gradient direction (any length; zero = flat region)
    vx, vy, vz : unit vector from the sample toward the viewer
    wx, wy, wz : sample position, world mm; x, y, z : the same in voxel indices

    Returns
    -------
    (fr, fg, fb, sr, sg, sb) : the shaded colour is ``c * f + s`` (straight
    colour), or ``C * f + alpha * s`` premultiplied. Where the gradient is
    zero every light counts as head-on (diffuse 1, no specular).
    """
    gl = np.sqrt(gx * gx + gy * gy + gz * gz)
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
    fr = ka
    fg = ka
    fb = ka
    sr = 0.0
    sg = 0.0
    sb = 0.0
    for l in range(nlights):
        lx = lights[l, L_POS] - wx
        ly = lights[l, L_POS + 1] - wy
        lz = lights[l, L_POS + 2] - wz
        d = np.sqrt(lx * lx + ly * ly + lz * lz)
        if d > 0.0:
            lx /= d
            ly /= d
            lz /= d
        spot = spot_factor(-lx, -ly, -lz, lights[l, L_DIR], lights[l, L_DIR + 1], lights[l, L_DIR + 2],
                           lights[l, L_EXP])
        if spot <= 0.0:
            continue
        vis = light_visibility(vol, lights, l, x, y, z, wx, wy, wz)
        w = spot * vis
        if flat:
            diff = 1.0
            spec = 0.0
        else:
            diff, spec = phong_terms(nx, ny, nz, lx, ly, lz, vx, vy, vz, shininess)
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
