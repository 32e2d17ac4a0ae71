"""One view ray in world and voxel-index space, its drawn interval and sample grid (see ``_march``).

A *part* (``Settings.part``: one brick of a volume drawn out of core,
:mod:`volumen.render.bricked`) samples the grid of the whole region (``Arrays.whole``:
interval, jitter, count, so ``t`` and the first and last samples' segments are
those of the whole ray) and takes of it the samples ``k0 <= k < k1`` that fall
in its own region (``Arrays.geo``), starting at the opacity ``a0`` the parts
in front accumulated (``Arrays.carry``): the ray then stops where the whole
ray stops. Two parts sharing a face compute the same ``k`` there, so every
sample falls in exactly one part.
"""

from __future__ import annotations

import math
from typing import NamedTuple

from ...jit import njit
from ._bspline import reconstruct
from ._geometry import primary_ray, ray_interval, to_index
from ._sample import jitter01

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
    k0: int     #: first sample drawn (0 unless a part)
    k1: int     #: one past the last sample drawn (n unless a part)
    a0: float   #: opacity carried in (0 unless a part)


@njit(cache=True, fastmath=False)
def _lattice_index(t, ds, jit):
    """The first whole m with (m + jit) ds >= t (strict IEEE arithmetic: a box face shared by two bricks gives
    both the same m)."""
    return int(math.ceil(t / ds - jit))


@njit(cache=True, fastmath=False)
def _grid_index(t, tw0, tw1, t0, ds, jit, n):
    """The first sample k of the grid (``t0 + (k + jit) ds``, k < n, of the whole interval [tw0, tw1]) with
    ``t_k >= t``, for a part's region boundary ``t`` (strict IEEE arithmetic, as ``_lattice_index``). A boundary
    within a millionth of a step of the whole ray's ends is that end (a part's face on the whole volume's face,
    computed through the part's own index transform, may miss it by a rounding error)."""
    if t <= tw0 + 1e-6 * ds:
        return 0
    if t >= tw1 - 1e-6 * ds:
        return n
    return min(max(int(math.ceil((t - t0) / ds - jit)), 0), n)


@njit(cache=True, fastmath=True, inline="always")
def begin_ray(px, py, a, s):
    """The :class:`Ray` of pixel (px, py); its ``t1 < t0`` when it misses the drawn region."""
    ox, oy, oz, dx, dy, dz = primary_ray(a.cam, px, py)
    t0, t1 = ray_interval(a.cam, a.whole, a.planes, s.nplanes, (ox, oy, oz), (dx, dy, dz))
    tw0, tw1 = t0, t1
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
    k0, k1, a0 = 0, n, 0.0
    if s.part and t1 >= t0:
        b0, b1 = ray_interval(a.cam, a.geo, a.planes, s.nplanes, (ox, oy, oz), (dx, dy, dz))
        k0 = _grid_index(b0, tw0, tw1, t0, s.ds, jit, n)
        k1 = _grid_index(b1, tw0, tw1, t0, s.ds, jit, n) if b1 >= b0 else k0
        a0 = a.carry[py, px]
    return Ray(ox, oy, oz, dx, dy, dz, oi, oj, ok, di, dj, dk, t0, t1, jit, n, k0, k1, a0)


@njit(cache=True, fastmath=True, inline="always")
def sample_at(r, a, s, t):
    """The reconstructed value at parameter ``t`` of the ray."""
    return reconstruct(s.recon, a.vol, s.sample_offset, s.sample_scale, r.oi + t * r.di, r.oj + t * r.dj,
                       r.ok + t * r.dk, s.nearest)
