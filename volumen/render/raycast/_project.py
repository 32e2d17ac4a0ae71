"""The projection modes' pieces: maximum, minimum and mean of the samples along the ray.

mip / minip: the largest / smallest sample; depth = where it was first met.
average: the mean of the samples taken; depth = the ray's entry ``t0``. The
pixel is the value's colour and opacity from the (uncorrected) table, and
``value`` the projected value in data units. State: ``(value, depth)`` (mip;
minip keeps the largest negated value) or ``(sum, count)`` (average).

The three are one kernel (the :class:`~._pieces.Projection` tag): the frame's ``Settings.proj`` picks the
projection, a branch every ray of the frame takes the same way.
"""

from __future__ import annotations

from numba import njit

from ._frame import FAR
from ._pieces import PROJECTIONS, Projection, eager, finish, init, radius, step

__all__ = []

#: ``Settings.proj`` of each projection (its place in ``_pieces.PROJECTIONS``)
MIP, MINIP, AVERAGE = (PROJECTIONS.index(m) for m in ("mip", "minip", "average"))


@init.register(Projection)
@njit(cache=True, inline="always")
def _init(light, r, a, s):
    return ((0.0, 0.0) if s.proj == AVERAGE else (-FAR, FAR)), 0, False, False


@njit(cache=True, fastmath=True, inline="always")
def _signed(s, v):
    """The value the running extreme keeps: ``v`` for the maximum, ``-v`` for the minimum (a select, no branch)."""
    return v if s.proj == MIP else -v


@step.register(Projection)
@njit(cache=True, fastmath=True, inline="always")
def _step(light, r, a, s, st, k, t, v, have, span):
    if s.proj != AVERAGE:
        w = _signed(s, v)
        return ((w, t) if w > st[0] else st), 0, False
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


@finish.register(Projection)
@njit(cache=True, fastmath=True)
def _finish(light, r, a, s, st, taken, have, out, px, py):
    out.nsamp[py, px] = taken
    if s.proj != AVERAGE:
        if taken > 0:
            _write(a, s, _signed(s, st[0]), st[1], out, px, py)
    elif st[1] > 0.0:
        _write(a, s, st[0] / st[1], r.t0, out, px, py)


@radius.register(Projection)
@njit(cache=True, fastmath=True, inline="always")
def _radius(a, s, st, o, bk, bj, bi):
    """1 where the block cannot beat the running maximum (minimum); the mean takes every sample."""
    if s.proj == MIP:
        return 1 if a.bmax[bk, bj, bi] <= st[0] else 0
    if s.proj == MINIP:
        return 1 if -a.bmin[bk, bj, bi] <= st[0] else 0
    return 0


@eager.register(Projection)
@njit(cache=True, inline="always")
def _eager_no():
    return False
