"""The isosurface mode's pieces: the first place the value reaches the threshold along the ray.

The crossing is found between the sample below and the sample at/above the
threshold by 4 regula-falsi steps (:func:`iso_refine`); a ray whose entry is
already inside shows the cut (cap) at ``t0``. The pixel is the surface colour
lit by the light tag's model with the normal at the hit. State:
``(depth, previous value, previous t)``.
"""

from __future__ import annotations

from numba import njit

from ._frame import FAR
from ._pieces import Isosurface, eager, finish, init, radius, shade, step
from ._ray import sample_at
from ._sample import sample_normal, sample_value

__all__ = ["iso_refine"]


@njit(cache=True, fastmath=True)
def iso_refine(vol, nearest, iso, ta, fa, tb, fb, oi, oj, ok, di, dj, dk):
    """Threshold crossing between (ta, fa < iso) and (tb, fb >= iso): regula falsi, 4 steps."""
    for _ in range(4):
        tm = ta + (iso - fa) / (fb - fa) * (tb - ta)
        vm = sample_value(vol, oi + tm * di, oj + tm * dj, ok + tm * dk, nearest)
        if vm >= iso:
            tb = tm
            fb = vm
        else:
            ta = tm
            fa = vm
    if fb - fa <= 0.0:
        return tb
    return ta + (iso - fa) / (fb - fa) * (tb - ta)


@init.register(Isosurface)
@njit(cache=True, fastmath=True)
def _init(light, r, a, s):
    v = sample_at(r, a, s, r.t0)
    dep = r.t0 if v >= s.iso else FAR
    return (dep, v, r.t0), 1, dep < FAR, True


@step.register(Isosurface)
@njit(cache=True, fastmath=True)
def _step(light, r, a, s, st, k, t, v, have):
    if v < s.iso:
        return (FAR, v, t), 0, False
    vp, tp = st[1], st[2]
    extra = 0
    if not have:
        tp = max(t - s.ds, r.t0)
        vp = sample_at(r, a, s, tp)
        extra = 1
    dep = t if vp >= s.iso else iso_refine(a.vol, s.nearest, s.iso, tp, vp, t, v, r.oi, r.oj, r.ok, r.di, r.dj,
                                            r.dk)
    return (dep, v, t), extra, True


@finish.register(Isosurface)
@njit(cache=True, fastmath=True)
def _finish(light, r, a, s, st, taken, have, out, px, py):
    out.nsamp[py, px] = taken
    dep = st[0]
    if dep >= FAR:
        return
    x, y, z = r.oi + dep * r.di, r.oj + dep * r.dj, r.ok + dep * r.dk
    gx, gy, gz, code = sample_normal(a.nrm, x, y, z, s.nearest)
    fr, fg, fb, sr, sg, sb = shade(light, a, s, (gx, gy, gz), (-r.dx, -r.dy, -r.dz),
                                   (r.ox + dep * r.dx, r.oy + dep * r.dy, r.oz + dep * r.dz))
    out.rgba[py, px, 0] = min(s.iso_r * fr + sr, 1.0)
    out.rgba[py, px, 1] = min(s.iso_g * fg + sg, 1.0)
    out.rgba[py, px, 2] = min(s.iso_b * fb + sb, 1.0)
    out.rgba[py, px, 3] = 1.0
    out.depth[py, px] = dep


@radius.register(Isosurface)
@njit(cache=True, fastmath=True)
def _radius(a, st, bk, bj, bi):
    return int(a.bflag[bk, bj, bi])


@eager.register(Isosurface)
@njit(cache=True)
def _eager_yes():
    return True
