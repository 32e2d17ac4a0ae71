"""The projection modes' pieces: maximum, minimum and mean of the samples along the ray.

mip / minip: the largest / smallest sample; depth = where it was first met.
average: the mean of the samples taken; depth = the ray's entry ``t0``. The
pixel is the value's colour and opacity from the (uncorrected) table, and
``value`` the projected value in data units. State: :class:`ProjectionState`.

The three are one kernel (the :class:`~._pieces.Projection` tag): the frame's ``Settings.projection`` picks the
projection, a branch every ray of the frame takes the same way.
"""

from __future__ import annotations

from typing import NamedTuple

from ...jit import njit
from ._frame import FAR
from ._pieces import PROJECTIONS, Projection, eager, finish, init, radius, step

__all__ = ["ProjectionState"]

#: ``Settings.projection`` of each projection (its place in ``_pieces.PROJECTIONS``)
MIP, MINIP, AVERAGE = (PROJECTIONS.index(m) for m in ("mip", "minip", "average"))


class ProjectionState(NamedTuple):
    """What a projection ray carries from sample to sample (mip and minip use the first two fields, average the
    last two)."""

    extreme: float  #: the largest value so far (minip: the largest negated value, :func:`_signed`)
    depth: float    #: where ``extreme`` was first met
    value_sum: float    #: the sum of the values so far
    value_count: float  #: the number of values summed


@init.register(Projection)
@njit(cache=True, inline="always")
def _init(light, r, a, s):
    return ProjectionState(-FAR, FAR, 0.0, 0.0), 0, False, False


@njit(cache=True, fastmath=True, inline="always")
def _signed(s, v):
    """The value the running extreme keeps: ``v`` for the maximum, ``-v`` for the minimum (a select, no branch)."""
    return v if s.projection == MIP else -v


@step.register(Projection)
@njit(cache=True, fastmath=True, inline="always")
def _step(light, r, a, s, st, smp):
    t, v = smp.t, smp.v
    if s.projection != AVERAGE:
        w = _signed(s, v)
        return (ProjectionState(w, t, st.value_sum, st.value_count) if w > st.extreme else st), 0, False
    return ProjectionState(st.extreme, st.depth, st.value_sum + v, st.value_count + 1.0), 0, False


@njit(cache=True, fastmath=True)
def _write(a, s, v, dep, out, px, py):
    lut = a.lut
    idx = min(max(int(v + 0.5), 0), lut.shape[0] - 1)
    al = lut[idx, 3]
    for c in range(3):
        out.rgba[py, px, c] = lut[idx, c] * al
    out.rgba[py, px, 3] = al
    out.depth[py, px] = dep
    out.value[py, px] = s.value_min + v * s.value_scale


@finish.register(Projection)
@njit(cache=True, fastmath=True)
def _finish(light, r, a, s, st, end, pix):
    out, px, py = pix.out, pix.x, pix.y
    taken = end.taken
    out.nsamp[py, px] = taken
    if s.projection != AVERAGE:
        if taken > 0:
            _write(a, s, _signed(s, st.extreme), st.depth, out, px, py)
    elif st.value_count > 0.0:
        _write(a, s, st.value_sum / st.value_count, r.t0, out, px, py)


@radius.register(Projection)
@njit(cache=True, fastmath=True, inline="always")
def _radius(a, s, st, o, bk, bj, bi):
    """1 where the block cannot beat the running maximum (minimum); the mean takes every sample."""
    if s.projection == MIP:
        return 1 if a.bmax[bk, bj, bi] <= st.extreme else 0
    if s.projection == MINIP:
        return 1 if -a.bmin[bk, bj, bi] <= st.extreme else 0
    return 0


@eager.register(Projection)
@njit(cache=True, inline="always")
def _eager_no():
    return False
