"""The isosurface mode's pieces: the first threshold crossing along the ray, seen from the eye's side.

The side is the one the eye is on. A ray that enters the drawn region from
outside starts below the threshold (the side of the background): the
surface is where the value first rises to the threshold, and a ray whose
entry is already above it shows the cut (cap) at ``t0``. When the eye is
itself inside the drawn region (``t0`` is the camera's near distance), the
side is that of the value at ``t0``: an eye inside a region above the
threshold (an endoscope in a contrast-filled vessel, brighter than its wall)
sees the surface where the value first falls below it. The crossing is found
between the last sample on the eye's side and the first beyond it by 4
regula-falsi steps (:func:`iso_refine`). The pixel is the surface colour lit
by the light tag's model with the normal at the hit (two-sided: it faces the
eye). State: ``(depth, previous value, previous t, side)``, side +1 when
looking for a rise, -1 for a fall.
"""

from __future__ import annotations

from numba import njit

from ._bspline import normal, reconstruct
from ._frame import FAR
from ._geometry import C_NEAR
from ._pieces import Isosurface, Trilinear, eager, finish, init, radius, shade, step, uses_normals
from ._ray import sample_at

__all__ = ["iso_refine"]


@njit(cache=True, fastmath=True)
def _crossing(vol, norm, iso, side, ta, fa, tb, fb, o, d):
    """Crossing between ``ta`` (on the eye's side) and ``tb`` (beyond): regula falsi on ``side * (v - iso)``,
    4 steps. ``norm = (u0, ufac, nearest, recon)``: how ``vol`` is read (``_bspline.reconstruct``); ``o``, ``d``:
    the ray in voxel indices."""
    u0, ufac, nearest, recon = norm
    fa = side * (fa - iso)
    fb = side * (fb - iso)
    for _ in range(4):
        tm = ta + (0.0 - fa) / (fb - fa) * (tb - ta)
        vm = side * (reconstruct(recon, vol, u0, ufac, o[0] + tm * d[0], o[1] + tm * d[1], o[2] + tm * d[2],
                                 nearest) - iso)
        if vm >= 0.0:
            tb = tm
            fb = vm
        else:
            ta = tm
            fa = vm
    if fb - fa <= 0.0:
        return tb
    return ta + (0.0 - fa) / (fb - fa) * (tb - ta)


_TRILINEAR = Trilinear()


@njit(cache=True, fastmath=True)
def iso_refine(vol, nearest, iso, ta, fa, tb, fb, oi, oj, ok, di, dj, dk):
    """Threshold crossing between (ta, fa < iso) and (tb, fb >= iso): regula falsi, 4 steps."""
    return _crossing(vol, (0.0, 1.0, nearest, _TRILINEAR), iso, 1.0, ta, fa, tb, fb, (oi, oj, ok), (di, dj, dk))


@njit(cache=True, fastmath=True, inline="always")
def _beyond(v, iso, side):
    """Whether value ``v`` lies beyond the threshold, seen from ``side``."""
    return v >= iso if side > 0.0 else v < iso


@init.register(Isosurface)
@njit(cache=True, fastmath=True, inline="always")
def _init(light, r, a, s):
    v = sample_at(r, a, s, r.t0)
    eye_inside = r.t0 <= a.cam[C_NEAR]
    side = -1.0 if (eye_inside and v >= s.iso) else 1.0
    dep = r.t0 if _beyond(v, s.iso, side) else FAR
    return (dep, v, r.t0, side), 1, dep < FAR, True


@step.register(Isosurface)
@njit(cache=True, fastmath=True, inline="always")
def _step(light, r, a, s, st, k, t, v, have, span):
    side = st[3]
    if not _beyond(v, s.iso, side):
        return (FAR, v, t, side), 0, False
    vp, tp = st[1], st[2]
    extra = 0
    if not have:
        tp = max(t - s.ds, r.t0)
        vp = sample_at(r, a, s, tp)
        extra = 1
    dep = t
    if not _beyond(vp, s.iso, side):
        dep = _crossing(a.vol, (s.u0, s.ufac, s.nearest, s.recon), s.iso, side, tp, vp, t, v, (r.oi, r.oj, r.ok),
                        (r.di, r.dj, r.dk))
    return (dep, v, t, side), extra, True


@finish.register(Isosurface)
@njit(cache=True, fastmath=True)
def _finish(light, r, a, s, st, taken, have, out, px, py):
    out.nsamp[py, px] = taken
    dep = st[0]
    if dep >= FAR:
        return
    x, y, z = r.oi + dep * r.di, r.oj + dep * r.dj, r.ok + dep * r.dk
    gx, gy, gz, _ = normal(s.recon, a, x, y, z, s.nearest, uses_normals(light), False)
    fr, fg, fb, sr, sg, sb = shade(light, a, s, (gx, gy, gz), (-r.dx, -r.dy, -r.dz),
                                   (r.ox + dep * r.dx, r.oy + dep * r.dy, r.oz + dep * r.dz))
    out.rgba[py, px, 0] = min(s.iso_r * fr + sr, 1.0)
    out.rgba[py, px, 1] = min(s.iso_g * fg + sg, 1.0)
    out.rgba[py, px, 2] = min(s.iso_b * fb + sb, 1.0)
    out.rgba[py, px, 3] = 1.0
    out.depth[py, px] = dep


@radius.register(Isosurface)
@njit(cache=True, fastmath=True, inline="always")
def _radius(a, s, st, o, bk, bj, bi):
    if st[3] > 0.0:  # skip distances of the blocks no value of which reaches the threshold
        return int(a.bflag[o, bk, bj, bi])
    return 0  # looking for a fall: no block grid of those (rare: eye inside the surface)


@eager.register(Isosurface)
@njit(cache=True, inline="always")
def _eager_yes():
    return True
