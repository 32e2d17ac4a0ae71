"""Progressive Monte Carlo path tracing of the volume (in the manner of Exposure Render), kernels and driver.

The medium is the one of the ``scattering`` model (:mod:`._scatter`): extinction ``sigma_t = kext * tau(v) / ds0``,
albedo ``sigma_s / sigma_t`` times the transfer function's colour, Henyey-Greenstein phase of parameter ``g``.
Per pixel sample (the view ray through a point of the pixel drawn from the Sobol sequence: a picture's pixel is
the mean over its area, a box filter, so detail finer than a pixel is averaged, not aliased):

* free flights by delta tracking against the majorant grid (:mod:`._majorant`); a real collision is a
  scattering event;
* at each event, next-event estimation of one light, chosen among the scene's lights (or the studio rig's) and
  the environment in proportion to their power: a light's ``diffuse * E * spot * 4 pi p_HG``, an area-like
  light's from a point drawn uniformly in its ball; the environment's radiance in a direction drawn from its
  importance-sampling tables (:mod:`._environment`), weighted against the phase function's sampling of the same
  direction by the power heuristic (multiple importance sampling); each times a ratio-tracking transmittance
  to the light or the edge of the drawn region, from ``shadow_offset`` off the event for the lights (docs/design.md
  section 3: no self-shadowing), from the event itself for the environment (the paths it is weighted against
  see the whole medium);
* ``pt_bounces == 1`` (single scattering): the event also adds the environment's ambient term unshadowed (the
  uniform ``ambient``, or the map's ``_environment.sh_phase``) and the path ends: an unbiased estimator of
  exactly the ``scattering`` picture; more bounces: the path continues in a direction drawn from the phase
  function (Russian roulette after 3 events); a path leaving the volume sees the environment (MIS-weighted; the
  uniform environment of radiance ``ambient`` in full).

Random numbers: :mod:`._sobol` (an Owen-scrambled Sobol sequence per pixel for the first four events' decisions,
a hash beyond): reproducible, independent of threads and of how samples are split between calls. A pixel's
opacity is not sampled: it is ``1 - exp(-optical depth)`` along its view ray, marched once
(:func:`._features.view_features`, which also gives the denoiser's auxiliary pictures: the first event's expected
albedo and normal, free of noise), so colour and alpha agree at every sample count; the colour is premultiplied
by it in expectation (a path that meets no medium brings nothing). No allocation in the per-pixel functions: they
are callable from a CUDA kernel.
"""

from __future__ import annotations

import math
from typing import NamedTuple

from ...jit import claim, njit
from ..optics import hg_phase
from ._environment import env_pdf, env_radiance, env_sample, sh_phase
from ._features import NFEAT, event_albedo, view_features
from ._geometry import C_W, pixel_ray, ray_interval, region_interval
from ._majorant import free_flight, transmittance
from ._shade import L_COL, L_POS, L_RAD, light_vector
from ._sobol import SOBOL_DIMS, draw, path_key

__all__ = ["trace_path", "coverage_pixel", "sample_hg", "trace_tiles", "NACC", "NFEAT"]

#: channels of the accumulation buffer: radiance (3), hits, depth sum
NACC = 5
#: Sobol dimensions per event (the first SOBOL_DIMS // EVENT_DIMS events draw theirs from the sequence)
EVENT_DIMS = 8
_D_FLIGHT, _D_PICK, _D_LIGHT, _D_PHASE, _D_ROULETTE = 0, 1, 2, 5, 7
#: Sobol dimensions of the sample's point in its pixel: the roulette dimensions of events 0 and 1, which never
#: draw them (roulette starts after 3 events)
_D_PIXEL = (_D_ROULETTE, EVENT_DIMS + _D_ROULETTE)
#: sub-pixel points per axis of the pixel's opacity and denoiser features (a regular grid)
COVERAGE_GRID = 3


class Event(NamedTuple):
    """A scattering event of a path, as next-event estimation reads it."""

    point: tuple      #: where it happens, world mm
    direction: tuple  #: the direction the path arrived along (unit)
    number: int       #: events before it on the path (it picks its Sobol dimensions, ``_dim``)


@njit(cache=True, fastmath=True, inline="always")
def _dim(n, j):
    """The Sobol dimension of decision ``j`` at event ``n``, or -1 past the stratified events."""
    return n * EVENT_DIMS + j if (n + 1) * EVENT_DIMS <= SOBOL_DIMS else -1


@njit(cache=True, fastmath=True, inline="always")
def _u(key, n, j, ctr):
    """``(uniform, ctr)``: decision ``j`` of event ``n`` (its Sobol dimension, else the next hash dimension)."""
    d = _dim(n, j)
    if d >= 0:
        return draw(key, d), ctr
    return draw(key, ctr), ctr + 1


@njit(cache=True, fastmath=True)
def sample_hg(g, dx, dy, dz, u1, u2):
    """A direction drawn from the Henyey-Greenstein phase around unit ``d`` (cos theta = dot(new, d))."""
    if abs(g) < 1e-3:
        c = 1.0 - 2.0 * u1
    else:
        sq = (1.0 - g * g) / (1.0 - g + 2.0 * g * u1)
        c = (1.0 + g * g - sq * sq) / (2.0 * g)
    c = min(max(c, -1.0), 1.0)
    s = math.sqrt(max(0.0, 1.0 - c * c))
    phi = 2.0 * math.pi * u2
    # orthonormal basis around d (Frisvad / Duff et al.)
    sign = 1.0 if dz >= 0.0 else -1.0
    a = -1.0 / (sign + dz)
    b = dx * dy * a
    t1x, t1y, t1z = 1.0 + sign * dx * dx * a, sign * b, -sign * dx
    t2x, t2y, t2z = b, sign + dy * dy * a, -dy
    cp = math.cos(phi) * s
    sp = math.sin(phi) * s
    return (c * dx + cp * t1x + sp * t2x, c * dy + cp * t1y + sp * t2y, c * dz + cp * t1z + sp * t2z)


@njit(cache=True, fastmath=True, inline="always")
def _power(a, li):
    """Weight of light ``li`` in the choice of the light to sample: the luminance of its colour x intensity."""
    return 0.2126 * a.lights[li, L_COL] + 0.7152 * a.lights[li, L_COL + 1] + 0.0722 * a.lights[li, L_COL + 2]


@njit(cache=True, fastmath=True)
def _transmittance(a, s, w, lv, dist, off, key, ctr):
    """Ratio-tracking transmittance from ``w + off lv`` toward unit ``lv`` over ``dist - off`` mm within the
    drawn region: ``(T, ctr)``."""
    q = (w[0] + off * lv[0], w[1] + off * lv[1], w[2] + off * lv[2])
    ta, tb = region_interval(a.geo, a.planes, s.nplanes, q, lv, 0.0, dist - off)
    if not tb > ta:
        return 1.0, ctr
    return transmittance(a, s, q, lv, (ta, tb), key, ctr)


@njit(cache=True, fastmath=True, inline="always")
def _light_sample(a, s, li, ev, pick, key, ctr):
    """Light ``li`` reaching event ``ev`` (an :class:`Event`), per unit throughput, over its pick probability."""
    w, d, n = ev.point, ev.direction, ev.number
    rad = a.lights[li, L_RAD]
    qx, qy, qz = a.lights[li, L_POS], a.lights[li, L_POS + 1], a.lights[li, L_POS + 2]
    u1, ctr = _u(key, n, _D_LIGHT, ctr)
    u2, ctr = _u(key, n, _D_LIGHT + 1, ctr)
    u3, ctr = _u(key, n, _D_LIGHT + 2, ctr)
    if rad > 0.0:  # a point drawn uniformly in the light's ball
        r = rad * u1 ** (1.0 / 3.0)
        cz = 1.0 - 2.0 * u2
        sz = math.sqrt(max(0.0, 1.0 - cz * cz))
        qx += r * sz * math.cos(2.0 * math.pi * u3)
        qy += r * sz * math.sin(2.0 * math.pi * u3)
        qz += r * cz
    lx, ly, lz, dist, spot = light_vector(a.lights, li, w[0] - (qx - a.lights[li, L_POS]),
                                          w[1] - (qy - a.lights[li, L_POS + 1]), w[2] - (qz - a.lights[li, L_POS + 2]))
    if spot <= 0.0 or dist <= s.shadow_offset:
        return 0.0, 0.0, 0.0, ctr
    vis, ctr = _transmittance(a, s, w, (lx, ly, lz), dist, s.shadow_offset, key, ctr)
    e = s.diffuse * spot * 4.0 * math.pi * hg_phase(lx * d[0] + ly * d[1] + lz * d[2], s.phase_g) * vis / pick
    return e * a.lights[li, L_COL], e * a.lights[li, L_COL + 1], e * a.lights[li, L_COL + 2], ctr


@njit(cache=True, fastmath=True, inline="always")
def _env_sample(a, s, ev, pick, last, key, ctr):
    """The environment reaching event ``ev`` (an :class:`Event`) along a direction drawn from its tables,
    MIS-weighted against phase sampling unless the path ends here (``last``), over its pick probability."""
    w, d, n = ev.point, ev.direction, ev.number
    u1, ctr = _u(key, n, _D_LIGHT, ctr)
    u2, ctr = _u(key, n, _D_LIGHT + 1, ctr)
    lx, ly, lz, pdf = env_sample(a, u1, u2)
    if not pdf > 0.0:
        return 0.0, 0.0, 0.0, ctr
    ph = hg_phase(lx * d[0] + ly * d[1] + lz * d[2], s.phase_g)
    vis, ctr = _transmittance(a, s, w, (lx, ly, lz), 1e30, 0.0, key, ctr)  # exact: MIS pairs it with paths
    pn = pick * pdf
    mis = 1.0 if last else pn * pn / (pn * pn + ph * ph)
    er, eg, eb = env_radiance(a, lx, ly, lz)
    f = ph * vis * mis / pn
    return er * f, eg * f, eb * f, ctr


@njit(cache=True, fastmath=True)
def _next_event(a, s, ev, env_w, last, key, ctr):
    """One light (or the environment, of weight ``env_w``) reaching event ``ev`` (an :class:`Event`):
    ``(r, g, b, ctr)`` per unit throughput."""
    n = ev.number
    total = env_w
    for li in range(s.nlights):
        total += _power(a, li)
    if not total > 0.0:
        return 0.0, 0.0, 0.0, ctr
    u, ctr = _u(key, n, _D_PICK, ctr)
    x = u * total
    if x < env_w:
        return _env_sample(a, s, ev, env_w / total, last, key, ctr)
    acc = env_w
    li = s.nlights - 1
    for k in range(s.nlights):
        acc += _power(a, k)
        if x < acc:
            li = k
            break
    return _light_sample(a, s, li, ev, _power(a, li) / total, key, ctr)


@njit(cache=True, fastmath=True, inline="always")
def _roulette(tr, n, key, ctr):
    """Russian roulette after 3 events: ``(survives, throughput, ctr)``."""
    if n < 3:
        return True, tr, ctr
    q = max(tr[0], tr[1], tr[2])
    if q >= 1.0:
        return True, tr, ctr
    u, ctr = _u(key, n, _D_ROULETTE, ctr)
    if u >= q:
        return False, tr, ctr
    return True, (tr[0] / q, tr[1] / q, tr[2] / q), ctr


@njit(cache=True, fastmath=True, inline="always")
def _first_hit(t, px, py, acc):
    """Record the view ray's first event: hit count, depth."""
    acc[py, px, 3] += 1.0
    acc[py, px, 4] += t


@njit(cache=True, fastmath=True)
def trace_path(px, py, sample, a, s, acc):
    """Add one path-traced sample of pixel (px, py) to ``acc[py, px]`` (:data:`NACC` channels: radiance r, g, b,
    hits, depth sum); ``a``, ``s`` the packed frame (``_frame``)."""
    key = path_key(s.seed, py * int(a.cam[C_W]) + px, sample)
    ctr = SOBOL_DIMS
    ox, oy, oz, dx, dy, dz = pixel_ray(a.cam, px + draw(key, _D_PIXEL[0]), py + draw(key, _D_PIXEL[1]))
    o, d = (ox, oy, oz), (dx, dy, dz)
    ta, tb = ray_interval(a.cam, a.geo, a.planes, s.nplanes, (ox, oy, oz), (dx, dy, dz))
    if not tb > ta:
        return
    env_w = s.env_power if s.bounces > 1 else 0.0
    total = env_w
    for li in range(s.nlights):
        total += _power(a, li)
    env_pick = env_w / total if total > 0.0 else 0.0
    tr = (1.0, 1.0, 1.0)
    lr = lg = lb = 0.0
    n = 0
    ph_pdf = 0.0  # density of the phase sampling that chose the current direction
    while True:
        hit, t, idx, ctr = free_flight(a, s, o, d, (ta, tb), key, _dim(n, _D_FLIGHT), ctr)
        if not hit:
            if n > 0:  # the path leaves and sees the environment
                if s.env_mode == 0:
                    lr, lg, lb = lr + tr[0] * s.ambient, lg + tr[1] * s.ambient, lb + tr[2] * s.ambient
                else:
                    pe = env_pick * env_pdf(a, d[0], d[1], d[2])
                    mis = ph_pdf * ph_pdf / (ph_pdf * ph_pdf + pe * pe)
                    er, eg, eb = env_radiance(a, d[0], d[1], d[2])
                    lr, lg, lb = lr + tr[0] * er * mis, lg + tr[1] * eg * mis, lb + tr[2] * eb * mis
            break
        w = (o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2])
        c = event_albedo(a, s, idx, w)
        if n == 0:
            _first_hit(t, px, py, acc)
        tr = (tr[0] * s.albedo * c[0], tr[1] * s.albedo * c[1], tr[2] * s.albedo * c[2])
        last = n + 1 >= s.bounces
        er, eg, eb, ctr = _next_event(a, s, Event(w, d, n), env_w, last, key, ctr)
        lr, lg, lb = lr + tr[0] * er, lg + tr[1] * eg, lb + tr[2] * eb
        n += 1
        if s.bounces <= 1:  # single scattering: the unshadowed ambient term, then stop
            if s.env_mode == 0:
                er = eg = eb = s.ambient
            else:
                er, eg, eb = sh_phase(a, d[0], d[1], d[2], s.phase_g)
            lr, lg, lb = lr + tr[0] * er, lg + tr[1] * eg, lb + tr[2] * eb
            break
        if last:
            break
        alive, tr, ctr = _roulette(tr, n, key, ctr)
        if not alive:
            break
        u1, ctr = _u(key, n - 1, _D_PHASE, ctr)
        u2, ctr = _u(key, n - 1, _D_PHASE + 1, ctr)
        nx, ny, nz = sample_hg(s.phase_g, d[0], d[1], d[2], u1, u2)
        nl = math.sqrt(nx * nx + ny * ny + nz * nz)
        nd = (nx / nl, ny / nl, nz / nl)
        ph_pdf = hg_phase(nd[0] * d[0] + nd[1] * d[1] + nd[2] * d[2], s.phase_g)
        o, d = w, nd
        ta, tb = region_interval(a.geo, a.planes, s.nplanes, o, d, 0.0, 1e30)
        if not tb > ta:  # leaves the region at once: the environment, through no medium
            ta = tb = 0.0
    acc[py, px, 0] += lr
    acc[py, px, 1] += lg
    acc[py, px, 2] += lb


@njit(cache=True, fastmath=True)
def coverage_pixel(px, py, a, s, alpha, feat):
    """``alpha[py, px]``: the probability that a path of pixel (px, py) meets the medium (the pixel's opacity), the
    mean of ``1 - exp(-optical depth)`` over the view rays of a :data:`COVERAGE_GRID`-squared grid of points in the
    pixel; ``feat[py, px]`` the denoiser's features over the same rays (:func:`._features.view_features`: the
    first event's expected albedo and normal)."""
    for k in range(NFEAT):
        feat[py, px, k] = 0.0
    n = COVERAGE_GRID
    wt = 1.0 / (n * n)
    cov = 0.0
    for j in range(n):
        for i in range(n):
            ox, oy, oz, dx, dy, dz = pixel_ray(a.cam, px + (i + 0.5) / n, py + (j + 0.5) / n)
            ta, tb = ray_interval(a.cam, a.geo, a.planes, s.nplanes, (ox, oy, oz), (dx, dy, dz))
            if tb > ta:
                tau = view_features(a, s, ((ox, oy, oz), (dx, dy, dz)), (ta, tb), wt, feat, (px, py))
                cov += wt * (1.0 - math.exp(-tau))
    alpha[py, px] = cov


@njit(cache=True, fastmath=True, nogil=True, _nrt=False)
def trace_tiles(counter, order, tile, samples, a, s, buffers):
    """The tiles ``order[claim(counter)]`` (``volumen.jit.run_claiming``) until none is left: samples
    ``samples = (s0, s1)``, ``s0 .. s1 - 1``, of each pixel (none when ``s1 <= s0``) into ``acc``, and when
    ``s0 == 0`` its opacity into ``alpha`` and its denoiser features into ``feat`` (:func:`coverage_pixel`);
    ``buffers = (acc, alpha, feat)``."""
    s0, s1 = samples
    acc, alpha, feat = buffers
    h, w = acc.shape[0], acc.shape[1]
    ntx = (w + tile - 1) // tile
    n = claim(counter)
    while n < order.shape[0]:
        t = order[n]
        y0 = (t // ntx) * tile
        x0 = (t % ntx) * tile
        for py in range(y0, min(y0 + tile, h)):
            for px in range(x0, min(x0 + tile, w)):
                if s0 == 0:
                    coverage_pixel(px, py, a, s, alpha, feat)
                for k in range(s0, s1):
                    trace_path(px, py, k, a, s, acc)
        n = claim(counter)
