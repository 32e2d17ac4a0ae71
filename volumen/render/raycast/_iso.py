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
eye). State: :class:`IsoState`.
"""

from __future__ import annotations

from typing import NamedTuple

from ...jit import njit
from ._bspline import normal, reconstruct
from ._frame import FAR
from ._geometry import C_NEAR
from ._pieces import Isosurface, Trilinear, eager, finish, init, radius, shade, step, uses_normals
from ._ray import sample_at

__all__ = ["iso_refine", "IsoState"]


class IsoState(NamedTuple):
    """What an isosurface ray carries from sample to sample."""

    depth: float       #: the crossing found (``FAR``: none yet)
    prev_value: float  #: the previous sample's value
    prev_t: float      #: the previous sample's ray parameter
    side: float        #: +1.0 looking for a rise through the threshold, -1.0 for a fall


@njit(cache=True, fastmath=True)
def _crossing(vol, norm, iso, side, near, far, o, d):
    """Crossing between ``near = (ta, fa)`` (ray parameter and value on the eye's side) and ``far = (tb, fb)``
    (beyond): regula falsi on ``side * (v - iso)``, 4 steps. ``norm = (u0, ufac, nearest, recon)``: how ``vol`` is
    read (``_bspline.reconstruct``); ``o``, ``d``: the ray in voxel indices."""
    u0, ufac, nearest, recon = norm
    ta, fa = near
    tb, fb = far
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
def iso_refine(vol, nearest, iso, below, above, o, d):
    """Threshold crossing between ``below = (ta, fa < iso)`` and ``above = (tb, fb >= iso)`` (ray parameter and
    value) on the ray ``o + t d`` (voxel indices): regula falsi, 4 steps."""
    return _crossing(vol, (0.0, 1.0, nearest, _TRILINEAR), iso, 1.0, below, above, o, d)


@njit(cache=True, fastmath=True, inline="always")
def _beyond(v, iso, side):
    """Whether value ``v`` lies beyond the threshold, seen from ``side``."""
    return v >= iso if side > 0.0 else v < iso


@init.register(Isosurface)
@njit(cache=True, fastmath=True, inline="always")
def _init(light, r, a, s):
    v = sample_at(r, a, s, r.t0)
    eye_inside = r.t0 <= a.cam[C_NEAR]
    side = -1.0 if (eye_inside and v >= s.iso_value) else 1.0
    dep = r.t0 if _beyond(v, s.iso_value, side) else FAR
    return IsoState(dep, v, r.t0, side), 1, dep < FAR, True


@step.register(Isosurface)
@njit(cache=True, fastmath=True, inline="always")
def _step(light, r, a, s, st, smp):
    t, v = smp.t, smp.v
    side = st.side
    if not _beyond(v, s.iso_value, side):
        return IsoState(FAR, v, t, side), 0, False
    vp, tp = st.prev_value, st.prev_t
    extra = 0
    if not smp.have:
        tp = max(t - s.ds, r.t0)
        vp = sample_at(r, a, s, tp)
        extra = 1
    dep = t
    if not _beyond(vp, s.iso_value, side):
        dep = _crossing(a.vol, (s.sample_offset, s.sample_scale, s.nearest, s.recon), s.iso_value, side, (tp, vp),
                        (t, v), (r.oi, r.oj, r.ok), (r.di, r.dj, r.dk))
    return IsoState(dep, v, t, side), extra, True


@finish.register(Isosurface)
@njit(cache=True, fastmath=True)
def _finish(light, r, a, s, st, end, pix):
    out, px, py = pix.out, pix.x, pix.y
    out.nsamp[py, px] = end.taken
    dep = st.depth
    if dep >= FAR:
        return
    x, y, z = r.oi + dep * r.di, r.oj + dep * r.dj, r.ok + dep * r.dk
    gx, gy, gz, _ = normal(s.recon, a, x, y, z, s.nearest, uses_normals(light), False)
    fr, fg, fb, sr, sg, sb = shade(light, a, s, (gx, gy, gz), (-r.dx, -r.dy, -r.dz),
                                   (r.ox + dep * r.dx, r.oy + dep * r.dy, r.oz + dep * r.dz))
    out.rgba[py, px, 0] = min(s.iso_red * fr + sr, 1.0)
    out.rgba[py, px, 1] = min(s.iso_green * fg + sg, 1.0)
    out.rgba[py, px, 2] = min(s.iso_blue * fb + sb, 1.0)
    out.rgba[py, px, 3] = 1.0
    out.depth[py, px] = dep


@radius.register(Isosurface)
@njit(cache=True, fastmath=True, inline="always")
def _radius(a, s, st, o, bk, bj, bi):
    if st.side > 0.0:  # skip distances of the blocks no value of which reaches the threshold
        return int(a.skip_flags[o, bk, bj, bi])
    return 0  # looking for a fall: no block grid of those (rare: eye inside the surface)


@eager.register(Isosurface)
@njit(cache=True, inline="always")
def _eager_yes():
    return True
