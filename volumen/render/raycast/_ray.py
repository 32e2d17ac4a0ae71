"""One view ray in world and voxel-index space, its drawn interval and sample grid (see ``_march``)."""

from __future__ import annotations

import math
from typing import NamedTuple

from numba import njit

from ._geometry import primary_ray, ray_interval, to_index
from ._sample import jitter01, sample_table

__all__ = ["Ray", "begin_ray", "sample_at"]


class Ray(NamedTuple):
    """One view ray: world origin / unit direction, the same in voxel-index space, interval and sample grid."""

    ox: float
    oy: float
    oz: float
    dx: float
    dy: float
    dz: float
    oi: float
    oj: float
    ok: float
    di: float
    dj: float
    dk: float
    t0: float
    t1: float
    jit: float  #: jitter of the first sample, in steps
    n: int      #: samples on the grid


@njit(cache=True, fastmath=False)
def _lattice_index(t, ds, jit):
    """The first whole m with (m + jit) ds >= t (strict IEEE arithmetic: a box face shared by two bricks gives
    both the same m)."""
    return int(math.ceil(t / ds - jit))


@njit(cache=True, fastmath=True, inline="always")
def begin_ray(px, py, a, s):
    """The :class:`Ray` of pixel (px, py); its ``t1 < t0`` when it misses the drawn region."""
    ox, oy, oz, dx, dy, dz = primary_ray(a.cam, px, py)
    t0, t1 = ray_interval(a.cam, a.geo, a.planes, s.nplanes, ox, oy, oz, dx, dy, dz)
    oi, oj, ok = to_index(a.geo, ox, oy, oz, 1.0)
    di, dj, dk = to_index(a.geo, dx, dy, dz, 0.0)
    jit = jitter01(px, py, s.seed) if s.jitter else 0.0
    n = 1
    if t1 >= t0 and s.lattice:  # t = (m + jit) ds, t0 <= t < t1; r.t0 / r.t1 half a step around them
        m0 = _lattice_index(t0, s.ds, jit)
        n = _lattice_index(t1, s.ds, jit) - m0
        t0, t1, jit = (m0 + jit - 0.5) * s.ds, (m0 + jit + n - 0.5) * s.ds, 0.5
    elif t1 >= t0:
        n = max(int(math.floor((t1 - t0) / s.ds - jit + 1e-4)) + 1, 1)
    return Ray(ox, oy, oz, dx, dy, dz, oi, oj, ok, di, dj, dk, t0, t1, jit, n)


@njit(cache=True, fastmath=True, inline="always")
def sample_at(r, a, s, t):
    """The reconstructed value at parameter ``t`` of the ray."""
    return sample_table(a.vol, s.u0, s.ufac, r.oi + t * r.di, r.oj + t * r.dj, r.ok + t * r.dk, s.nearest)
