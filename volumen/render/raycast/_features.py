"""The denoiser's auxiliary pictures, free of noise: the albedo and normal expected at a view ray's first event.

A path's first scattering event along a view ray falls in the segment ``[t, t + dt]`` with probability
``T(t) (1 - exp(-sigma_t dt))`` (``T`` the transmittance from the eye). :func:`view_features` marches a view ray
once, deterministically, and sums the event's albedo (``albedo`` times the medium's colour, in [0, 1]) and normal
(minus the density gradient, unit, facing the eye) with those weights: the expectations of what the first events
of the paths along that ray average to, premultiplied by the probability of an event ``1 - exp(-optical depth)``,
whose optical depth it returns as well. The path tracer averages them over a regular grid of rays in the pixel
(``_pathtrace.coverage_pixel``), as its samples average over the pixel's area. Open Image
Denoise takes them as clean auxiliary pictures (``cleanAux``: not prefiltered); averaged from the paths' random
first events instead, they carried the picture's noise into the denoiser's guide.

The march is :func:`._majorant`'s grid walk: cells of zero majorant hold no medium and cost one step; in the
others, the midpoint rule with steps of at most ``h`` mm; it stops past an optical depth of 10.
"""

from __future__ import annotations

import math

from ...jit import njit
from ._bspline import reconstruct
from ._color import sample_rgb
from ._geometry import to_index
from ._majorant import advance_cell, grid_walk
from ._medium import depth_at, event_color, frame_medium

__all__ = ["view_features", "event_albedo", "medium_normal", "NFEAT"]

#: channels of the features: albedo r, g, b, normal x, y, z
NFEAT = 6


@njit(cache=True, fastmath=True, inline="always")
def event_albedo(a, s, idx, w):
    """Colour of a scattering event at world point ``w``: the table's (the label-aware classification's with a
    label map, ``_medium.event_color``), or the voxel's own in a colour volume."""
    x, y, z = to_index(a.geo, w[0], w[1], w[2], 1.0)
    if s.color:
        return sample_rgb(a.rgb, x, y, z, s.nearest)
    return event_color(frame_medium(a, s), x, y, z, idx)


@njit(cache=True, fastmath=True, inline="always")
def medium_normal(a, s, w, d):
    """Unit normal of the medium at world point ``w`` (minus its density gradient, through the index -> world
    gradient matrix ``Arrays.gradient_matrix``), turned toward the eye (against ``d``); (0, 0, 0) where the gradient
    vanishes."""
    x, y, z = to_index(a.geo, w[0], w[1], w[2], 1.0)
    r, v, u0, f = s.recon, a.vol, s.sample_offset, s.sample_scale
    gi = reconstruct(r, v, u0, f, x + 1.0, y, z, False) - reconstruct(r, v, u0, f, x - 1.0, y, z, False)
    gj = reconstruct(r, v, u0, f, x, y + 1.0, z, False) - reconstruct(r, v, u0, f, x, y - 1.0, z, False)
    gk = reconstruct(r, v, u0, f, x, y, z + 1.0, False) - reconstruct(r, v, u0, f, x, y, z - 1.0, False)
    m = a.gradient_matrix
    nx = -(m[0, 0] * gi + m[0, 1] * gj + m[0, 2] * gk)
    ny = -(m[1, 0] * gi + m[1, 1] * gj + m[1, 2] * gk)
    nz = -(m[2, 0] * gi + m[2, 1] * gj + m[2, 2] * gk)
    ln = math.sqrt(nx * nx + ny * ny + nz * nz)
    if not ln > 1e-9:
        return 0.0, 0.0, 0.0
    if nx * d[0] + ny * d[1] + nz * d[2] > 0.0:
        ln = -ln
    return nx / ln, ny / ln, nz / ln


@njit(cache=True, fastmath=True, inline="always")
def _add_event(a, s, w, d, idx, p, feat, pix):
    """Add the albedo and normal of an event at ``w`` (table index ``idx``), weighted by probability ``p``, to
    ``feat`` at pixel ``pix = (px, py)``."""
    px, py = pix
    c = event_albedo(a, s, idx, w)
    for k in range(3):
        feat[py, px, k] += p * min(max(s.albedo * c[k], 0.0), 1.0)
    nx, ny, nz = medium_normal(a, s, w, d)
    feat[py, px, 3] += p * nx
    feat[py, px, 4] += p * ny
    feat[py, px, 5] += p * nz


@njit(cache=True, fastmath=True)
def view_features(a, s, ray, span, wt, feat, pix):
    """March world ray ``ray = (w, d)``, ``w + t d``, over ``span = (t0, t1)`` in steps of at most ``s.ds``: add to
    ``feat[py, px]`` (:data:`NFEAT` channels, ``pix = (px, py)``) ``wt`` times the expected albedo and normal of
    its first event (premultiplied by the probability of one); returns the optical depth ``integral sigma_t dt``
    (``scale = kext / ds0`` turns the table's depth per reference step into 1/mm)."""
    w, d = ray
    t0, t1 = span
    scale = s.extinction_scale / s.ds0
    h = s.ds
    g = a.majorant
    o, dv, c, steps, nx, de = grid_walk(a, s, w, d, t0)
    med = frame_medium(a, s)
    t = t0
    tau = 0.0
    while t < t1 and tau < 10.0:
        tn = min(nx[0], nx[1], nx[2], t1)
        if g[c[2], c[1], c[0]] > 0.0 and tn > t:
            n = int(math.ceil((tn - t) / h))
            dt = (tn - t) / n
            for k in range(n):
                tm = t + (k + 0.5) * dt
                sg, idx = depth_at(med, o[0] + tm * dv[0], o[1] + tm * dv[1], o[2] + tm * dv[2])
                if sg > 0.0:
                    p = math.exp(-tau) * -math.expm1(-sg * scale * dt)
                    if p > 1e-6:
                        _add_event(a, s, (w[0] + tm * d[0], w[1] + tm * d[1], w[2] + tm * d[2]), d, idx, p * wt,
                                   feat, pix)
                    tau += sg * scale * dt
        t = tn
        c, nx, inside = advance_cell(g, c, steps, nx, de)
        if not inside:
            break
    return tau
