"""The projection modes' pieces: maximum, minimum and mean of the samples along the ray.

mip / minip: the largest / smallest sample; depth = where it was first met.
average: the mean of the samples taken; depth = the ray's entry ``t0``. The
pixel is the value's colour and opacity from the (uncorrected) table, and
``value`` the projected value in data units. State: ``(value, depth)`` (mip,
minip) or ``(sum, count)`` (average).
"""

from __future__ import annotations

from numba import njit

from ._frame import FAR
from ._pieces import Average, Minip, Mip, eager, finish, init, radius, step

__all__ = []


@init.register(Mip)
@njit(cache=True, inline="always")
def _init_mip(light, r, a, s):
    return (-FAR, FAR), 0, False, False


@init.register(Minip)
@njit(cache=True, inline="always")
def _init_minip(light, r, a, s):
    return (FAR, FAR), 0, False, False


@init.register(Average)
@njit(cache=True, inline="always")
def _init_average(light, r, a, s):
    return (0.0, 0.0), 0, False, False


@step.register(Mip)
@njit(cache=True, fastmath=True, inline="always")
def _step_mip(light, r, a, s, st, k, t, v, have, span):
    return ((v, t) if v > st[0] else st), 0, False


@step.register(Minip)
@njit(cache=True, fastmath=True, inline="always")
def _step_minip(light, r, a, s, st, k, t, v, have, span):
    return ((v, t) if v < st[0] else st), 0, False


@step.register(Average)
@njit(cache=True, fastmath=True, inline="always")
def _step_average(light, r, a, s, st, k, t, v, have, span):
    return (st[0] + v, st[1] + 1.0), 0, False


@njit(cache=True, fastmath=True)
def _write(a, s, v, dep, out, px, py):
    lut = a.lut
    idx = min(max(int(v + 0.5), 0), lut.shape[0] - 1)
    al = lut[idx, 3]
    for c in range(3):
        out.rgba[py, px, c] = lut[idx, c] * al
    out.rgba[py, px, 3] = al
    out.depth[py, px] = dep
    out.value[py, px] = s.vmin + v * s.vscale


@finish.register(Mip, Minip)
@njit(cache=True, fastmath=True)
def _finish_extreme(light, r, a, s, st, taken, have, out, px, py):
    out.nsamp[py, px] = taken
    if taken > 0:
        _write(a, s, st[0], st[1], out, px, py)


@finish.register(Average)
@njit(cache=True, fastmath=True)
def _finish_average(light, r, a, s, st, taken, have, out, px, py):
    out.nsamp[py, px] = taken
    if st[1] > 0.0:
        _write(a, s, st[0] / st[1], r.t0, out, px, py)


@radius.register(Mip)
@njit(cache=True, fastmath=True, inline="always")
def _radius_mip(a, st, o, bk, bj, bi):
    return 1 if a.bmax[bk, bj, bi] <= st[0] else 0


@radius.register(Minip)
@njit(cache=True, fastmath=True, inline="always")
def _radius_minip(a, st, o, bk, bj, bi):
    return 1 if a.bmin[bk, bj, bi] >= st[0] else 0


@radius.register(Average)
@njit(cache=True, inline="always")
def _radius_none(a, st, o, bk, bj, bi):
    return 0


@eager.register(Mip, Minip, Average)
@njit(cache=True, inline="always")
def _eager_no():
    return False
