"""Direct shadow rays: the transmittance from a point toward a light, marched through the volume.

The reference definition (DESIGN.md section 3) that the illumination volumes
(:mod:`._lightvol`) must match: along the ray ``y + s L`` (world mm, ``L`` unit,
``y`` already moved ``shadow_offset`` off the sample toward the light), over
``s`` in ``[0, distance to the light]`` intersected with the drawn region
(volume box, crop box, clip planes -- so a cropped face is lit), the optical
depth ``tau = integral of -ln(1 - alpha(v(s))) ds / ds0`` by the trapezoid rule
on samples ``step`` apart (plus the exit point), with ``alpha`` the transfer
function's opacity per reference step of the trilinear value. The light
reaching the point is ``exp(-kext * tau)`` = ``1 - opacity accumulated``
(``kext = 1`` for shadows; ``sigma_a + sigma_s`` for scattering).
"""

from __future__ import annotations

import math

from numba import njit

from ._geometry import region_interval, to_index
from ._sample import sample_table

__all__ = ["shadow_transmittance", "TAU_STOP"]

#: optical depth past which a shadow ray stops (transmittance < 1e-6)
TAU_STOP = 14.0


@njit(cache=True, fastmath=True)
def _sig(field, x, y, z):
    vol, sig, u0, ufac = field
    v = sample_table(vol, u0, ufac, x, y, z, False)
    return sig[min(max(int(v + 0.5), 0), sig.shape[0] - 1)]


@njit(cache=True, fastmath=True)
def shadow_transmittance(field, geo, planes, nplanes, ox, oy, oz, lx, ly, lz, smax, step, ds0, kext):
    """Transmittance ``exp(-kext * tau)`` from world point ``o`` along unit ``L`` over ``[0, smax]`` mm.

    Parameters
    ----------
    field : (vol, sig, u0, ufac)
        The samples ``[z, y, x]`` read as ``_sample.sample_table`` does, and the
        optical depth per reference step of each table entry ``sig`` (NLUT,)
    geo, planes, nplanes : packed geometry (``_geometry``)
    ox, oy, oz : start, world mm; lx, ly, lz : unit direction toward the light
    smax : distance to the light, mm
    step, ds0 : march step and reference step, mm
    kext : extinction scale
    """
    ta, tb = region_interval(geo, planes, nplanes, ox, oy, oz, lx, ly, lz, 0.0, smax)
    if not tb > ta:
        return 1.0
    oi, oj, ok = to_index(geo, ox, oy, oz, 1.0)
    di, dj, dk = to_index(geo, lx, ly, lz, 0.0)
    stop = TAU_STOP * ds0 / kext
    sp = _sig(field, oi + ta * di, oj + ta * dj, ok + ta * dk)
    acc = 0.0  # integral of sigma ds, sigma in reference-step units, s in mm
    t = ta
    m = int((tb - ta) / step)
    for j in range(1, m + 1):
        t = ta + j * step
        s = _sig(field, oi + t * di, oj + t * dj, ok + t * dk)
        acc += 0.5 * (sp + s) * step
        sp = s
        if acc > stop:
            return 0.0
    if tb - t > 1e-6 * step:
        s = _sig(field, oi + tb * di, oj + tb * dj, ok + tb * dk)
        acc += 0.5 * (sp + s) * (tb - t)
    return math.exp(-kext * acc / ds0)
