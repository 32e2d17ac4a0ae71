"""Progressive Monte Carlo path tracing of the volume (in the manner of Exposure Render).

The medium is the one of the ``scattering`` model (:mod:`._scatter`):
extinction ``sigma_t = kext * tau(v) / ds0``, albedo ``sigma_s / sigma_t``
times the transfer function's colour, Henyey-Greenstein phase of parameter
``g``. Per pixel sample (the ray through the pixel centre):

* free flights by delta (Woodcock) tracking against the global majorant
  ``max sigma_t``; a real collision is a scattering event (its probability
  along the view ray is the opacity, which is the pixel's alpha);
* at each event, next-event estimation toward every light: the light's
  ``diffuse * E * spot * 4 pi p_HG`` times its transmittance, estimated by
  ratio tracking from ``shadow_offset`` off the event to the light or the edge
  of the drawn region (area-like lights: a point drawn in the light's ball);
* ``pt_bounces == 1`` (single scattering): the event also adds the ambient
  term unshadowed and the path ends -- an unbiased estimator of exactly the
  ``scattering`` picture; more bounces: the path continues in a direction
  drawn from the phase function (Russian roulette after 3 events), and paths
  leaving the volume after a scattering event see the uniform environment of
  radiance ``ambient``.

Random numbers come from a counter-based hash of (seed, pixel, sample index,
draw number), so every sample is reproducible and independent of threads and
of how the samples are split between calls. No allocation inside the
per-pixel function: it is callable from a CUDA kernel.
"""

from __future__ import annotations

import math
import time
from dataclasses import replace

import numpy as np
from numba import njit, prange

from ._color import sample_rgb
from ._cpu import TILE, tile_order
from ._geometry import primary_ray, ray_interval, region_interval, to_index
from ._medium import depth_at, depth_bound, event_color, frame_medium, label_scale
from ._pack import pack_frame
from ._scatter import phase_weight
from ._shade import L_COL, L_RAD, light_vector

__all__ = ["PathTracer", "rand01", "sample_hg", "trace_path"]

_M1 = np.uint64(0xBF58476D1CE4E5B9)
_M2 = np.uint64(0x94D049BB133111EB)
_GOLD = np.uint64(0x9E3779B97F4A7C15)
_K1 = np.uint64(0xD6E8FEB86659FD93)
_K2 = np.uint64(0xA0761D6478BD642F)


@njit(cache=True)
def _mix(h):
    """splitmix64 finalizer (uint64 -> uint64)."""
    h = (h ^ (h >> np.uint64(30))) * _M1
    h = (h ^ (h >> np.uint64(27))) * _M2
    return h ^ (h >> np.uint64(31))


@njit(cache=True)
def path_key(seed, pixel, sample):
    """The random stream of one pixel sample: a hash of (seed, pixel index, sample index)."""
    return _mix(_mix(np.uint64(seed) * _K1 + np.uint64(pixel)) ^ (np.uint64(sample) * _K2))


@njit(cache=True)
def rand01(key, ctr):
    """Uniform in [0, 1): draw number ``ctr`` of stream ``key`` (53 random bits)."""
    return np.float64(_mix(key + np.uint64(ctr) * _GOLD) >> np.uint64(11)) * (1.0 / 9007199254740992.0)


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


@njit(cache=True, fastmath=True)
def _sigma(med, oi, oj, ok, di, dj, dk, t, scale):
    tau, idx = depth_at(med, oi + t * di, oj + t * dj, ok + t * dk)
    return tau * scale, idx


@njit(cache=True, fastmath=True)
def _ratio_tracking(med, geo, planes, nplanes, ox, oy, oz, lx, ly, lz, smax, scale, smaj, key, ctr):
    """Unbiased transmittance estimate along ``o + s L``, s in [0, smax] within the region; returns (T, ctr)."""
    ta, tb = region_interval(geo, planes, nplanes, ox, oy, oz, lx, ly, lz, 0.0, smax)
    if not tb > ta:
        return 1.0, ctr
    oi, oj, ok = to_index(geo, ox, oy, oz, 1.0)
    di, dj, dk = to_index(geo, lx, ly, lz, 0.0)
    tr = 1.0
    t = ta
    while True:
        t -= math.log(1.0 - rand01(key, ctr)) / smaj
        ctr += 1
        if t >= tb:
            break
        s, _ = _sigma(med, oi, oj, ok, di, dj, dk, t, scale)
        tr *= 1.0 - s / smaj
        if tr < 0.05:  # Russian roulette keeps the estimate unbiased
            if rand01(key, ctr) < 0.5:
                ctr += 1
                return 0.0, ctr
            ctr += 1
            tr *= 2.0
    return tr, ctr


@njit(cache=True, fastmath=True)
def _free_flight(a, s, o, d, ta, tb, scale, smaj, key, ctr):
    """Delta (Woodcock) tracking from ``ta``: ``(hit, t, table index, ctr)`` of the first real collision."""
    oi, oj, ok = to_index(a.geo, o[0], o[1], o[2], 1.0)
    di, dj, dk = to_index(a.geo, d[0], d[1], d[2], 0.0)
    t = ta
    while True:
        t -= math.log(1.0 - rand01(key, ctr)) / smaj
        ctr += 1
        if t >= tb:
            return False, t, 0, ctr
        sg, idx = _sigma(frame_medium(a, s), oi, oj, ok, di, dj, dk, t, scale)
        u = rand01(key, ctr)
        ctr += 1
        if u * smaj < sg:
            return True, t, idx, ctr


@njit(cache=True, fastmath=True, inline="always")
def _albedo_color(a, s, idx, w):
    """Colour of a scattering event at world point ``w``: the table's (the label-aware classification's with a
    label map, ``_medium.event_color``), or the voxel's own in a colour volume."""
    x, y, z = to_index(a.geo, w[0], w[1], w[2], 1.0)
    if s.color:
        return sample_rgb(a.rgb, x, y, z, s.nearest)
    return event_color(frame_medium(a, s), x, y, z, idx)


@njit(cache=True, fastmath=True)
def _light_point(a, light, w, key, ctr):
    """The event ``w`` shifted by a point of area-like light ``light``'s ball (itself for a point light)."""
    rad = a.lights[light, L_RAD]
    if not rad > 0.0:
        return w, ctr
    while True:
        ax = 2.0 * rand01(key, ctr) - 1.0
        ay = 2.0 * rand01(key, ctr + 1) - 1.0
        az = 2.0 * rand01(key, ctr + 2) - 1.0
        ctr += 3
        if ax * ax + ay * ay + az * az <= 1.0:
            return (w[0] - rad * ax, w[1] - rad * ay, w[2] - rad * az), ctr


@njit(cache=True, fastmath=True)
def _next_event(a, s, w, d, scale, smaj, key, ctr):
    """Light reaching the event ``w`` (direction of travel ``d``) from every light, per unit throughput:
    ``(r, g, b, ctr)``."""
    lr = lg = lb = 0.0
    off = s.sh_off
    for li in range(s.nlights):
        q, ctr = _light_point(a, li, w, key, ctr)
        lx, ly, lz, dist, spot = light_vector(a.lights, li, q[0], q[1], q[2])
        if spot <= 0.0 or dist <= off:
            continue
        ph = phase_weight(lx, ly, lz, -d[0], -d[1], -d[2], s.g)
        vis, ctr = _ratio_tracking(frame_medium(a, s), a.geo, a.planes, s.nplanes, w[0] + off * lx,
                                   w[1] + off * ly, w[2] + off * lz, lx, ly, lz, dist - off, scale, smaj, key, ctr)
        e = s.kd * spot * ph * vis
        lr += e * a.lights[li, L_COL]
        lg += e * a.lights[li, L_COL + 1]
        lb += e * a.lights[li, L_COL + 2]
    return lr, lg, lb, ctr


@njit(cache=True, fastmath=True)
def _roulette(tr, n, key, ctr):
    """Russian roulette after 3 events: ``(survives, throughput, ctr)``."""
    if n < 3:
        return True, tr, ctr
    q = max(tr[0], tr[1], tr[2])
    if q >= 1.0:
        return True, tr, ctr
    if rand01(key, ctr) >= q:
        return False, tr, ctr
    return True, (tr[0] / q, tr[1] / q, tr[2] / q), ctr + 1


@njit(cache=True, fastmath=True)
def trace_path(px, py, sample, a, s, smaj, acc):
    """Add one path-traced sample of pixel (px, py) to ``acc[py, px]`` = (r, g, b, alpha, depth sum).

    ``smaj`` is the majorant extinction (1/mm); ``a``, ``s`` the packed frame
    (``_frame``). Radiance is premultiplied (transparent background).
    """
    key = path_key(s.seed, py * int(a.cam[14]) + px, sample)
    ctr = 0
    ox, oy, oz, dx, dy, dz = primary_ray(a.cam, px, py)
    o, d = (ox, oy, oz), (dx, dy, dz)
    ta, tb = ray_interval(a.cam, a.geo, a.planes, s.nplanes, ox, oy, oz, dx, dy, dz)
    if not tb > ta:
        return
    scale = s.kext / s.ds0
    tr = (1.0, 1.0, 1.0)
    lr = lg = lb = 0.0
    n = 0
    env = False  # the path ends seeing the environment (after a scattering event)
    while True:
        hit, t, idx, ctr = _free_flight(a, s, o, d, ta, tb, scale, smaj, key, ctr)
        if not hit:
            env = n > 0
            break
        w = (o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2])
        if n == 0:
            acc[py, px, 3] += 1.0
            acc[py, px, 4] += t
        cr, cg, cb = _albedo_color(a, s, idx, w)
        tr = (tr[0] * s.albedo * cr, tr[1] * s.albedo * cg, tr[2] * s.albedo * cb)
        n += 1
        er, eg, eb, ctr = _next_event(a, s, w, d, scale, smaj, key, ctr)
        lr, lg, lb = lr + tr[0] * er, lg + tr[1] * eg, lb + tr[2] * eb
        if s.bounces <= 1:  # single scattering: the unshadowed ambient term, then stop
            env = True
            break
        if n >= s.bounces:
            break
        alive, tr, ctr = _roulette(tr, n, key, ctr)
        if not alive:
            break
        nx, ny, nz = sample_hg(s.g, d[0], d[1], d[2], rand01(key, ctr), rand01(key, ctr + 1))
        ctr += 2
        nl = math.sqrt(nx * nx + ny * ny + nz * nz)
        o, d = w, (nx / nl, ny / nl, nz / nl)
        ta, tb = region_interval(a.geo, a.planes, s.nplanes, o[0], o[1], o[2], d[0], d[1], d[2], 0.0, 1e30)
        if not tb > ta:
            env = True
            break
    if env:
        lr, lg, lb = lr + tr[0] * s.ka, lg + tr[1] * s.ka, lb + tr[2] * s.ka
    acc[py, px, 0] += lr
    acc[py, px, 1] += lg
    acc[py, px, 2] += lb


@njit(cache=True, fastmath=True, _nrt=False)
def _trace_path_cpu(px, py, k, a, s, smaj, acc):
    """``trace_path`` without reference counting (see ``_march._trace_pixel_cpu``)."""
    trace_path(px, py, k, a, s, smaj, acc)


@njit(parallel=True, fastmath=True, cache=True)
def _trace_tiles(order, tile, s0, s1, a, s, smaj, acc):
    h, w = acc.shape[0], acc.shape[1]
    ntx = (w + tile - 1) // tile
    for n in prange(order.shape[0]):
        t = order[n]
        y0 = (t // ntx) * tile
        x0 = (t % ntx) * tile
        for py in range(y0, min(y0 + tile, h)):
            for px in range(x0, min(x0 + tile, w)):
                for k in range(s0, s1):
                    _trace_path_cpu(px, py, k, a, s, smaj, acc)


class PathTracer:
    """A progressive path tracer of one (scene, camera, size): each :meth:`step` adds samples per pixel.

    Parameters
    ----------
    scene : Scene
        Mode ``composite``; its shading settings give the medium (``sigma_a``,
        ``sigma_s``, ``phase_g``), ``ambient`` (environment), ``diffuse``
        (light scale), ``pt_bounces`` and ``shadow_offset``; ``sampling.seed``
        seeds the random numbers. The shading mode itself is ignored.
    camera : Camera
    size : (width, height), pixels

    Attributes
    ----------
    spp : int
        Samples per pixel accumulated so far.
    """

    def __init__(self, scene, camera, size):
        if scene.mode != "composite":
            raise ValueError(f"path tracing needs mode 'composite', got {scene.mode!r}")
        scene = replace(scene, shading=replace(scene.shading, mode="pathtrace"))
        self.frame = pack_frame(scene, camera, size)
        w, h = self.frame.size
        self.acc = np.zeros((h, w, 5), np.float64)
        self.spp = 0
        self.seconds = 0.0
        f = self.frame
        a, st = f.arrays, f.settings
        tau = depth_bound(a.sig, a.llut, label_scale(st.ds, st.ds0, st.kext), st.nlab)
        self.smaj = max(tau * st.kext / st.ds0, 1e-9)

    #: the ``stats["backend"]`` of the images
    backend = "cpu"

    def _accumulate(self, s0: int, s1: int) -> None:
        """Add samples ``s0 .. s1 - 1`` of every pixel into ``self.acc`` (h, w, 5)."""
        f = self.frame
        w, h = f.size
        _trace_tiles(tile_order(w, h), TILE, s0, s1, f.arrays, f.settings, self.smaj, self.acc)

    def reset(self) -> None:
        """Forget the accumulated samples."""
        self.acc[...] = 0.0
        self.spp = 0
        self.seconds = 0.0

    def step(self, n_samples: int = 1):
        """Add ``n_samples`` samples per pixel; returns the current :class:`~volumen.core.Image`.

        ``rgba`` is the running mean (premultiplied, clipped to [0, 1], colour
        at most alpha: multiple scattering can make a medium brighter than
        white, which saturates, as on a display);
        ``depth`` the mean distance (mm) of the first scattering event along
        the view ray (inf where none happened); ``stats["spp"]`` the samples per
        pixel so far, ``stats["timings"]["kernel"]`` the seconds of this step.
        """
        from ...core import Image

        n = int(n_samples)
        if n < 1:
            raise ValueError(f"n_samples must be >= 1, got {n_samples!r}")
        f = self.frame
        w, h = f.size
        t = time.perf_counter()
        self._accumulate(self.spp, self.spp + n)
        dt = time.perf_counter() - t
        self.spp += n
        self.seconds += dt
        mean = np.clip(self.acc[..., :4] / self.spp, 0.0, 1.0)
        mean[..., :3] = np.minimum(mean[..., :3], mean[..., 3:4])  # straight colour saturates at 1
        rgba = mean.astype(np.float32)
        hits = self.acc[..., 3]
        with np.errstate(invalid="ignore", divide="ignore"):
            depth = np.where(hits > 0, self.acc[..., 4] / np.maximum(hits, 1), np.inf).astype(np.float32)
        timings = dict(f.timings, kernel=dt, total=self.seconds)
        stats = {"timings": timings, "spp": self.spp, "samples": self.spp * w * h, "rays": w * h,
                 "rays_hit": int(np.count_nonzero(hits)), "backend": self.backend, "mode": "composite",
                 "shading": "pathtrace", "step_mm": f.ds, "reference_step_mm": f.ds0}
        return Image(rgba=rgba, depth=depth, stats=stats)
