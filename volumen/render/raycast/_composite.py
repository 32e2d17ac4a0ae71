"""The composite modes' pieces: emission-absorption, post-classified (``Composite``; through the label map:
``LabelledComposite``) or pre-integrated.

Post-classified samples each stand for the part of ``[t0, t1]`` nearer to
them than to their neighbours (``ds`` inside, less at the ends), opacity
corrected to that length, so a ray's total length is exact whatever the step.
With adaptive sampling (``_march``) a sample in a coarse block stands for ``span`` steps from half a step before
it, corrected alike; the depth there is the merged sample's own, up to ``span - 1`` steps nearer than at full
rate (in tissue that classifies below 0.1 opacity a step).
Pre-integrated: sample ``k`` closes the segment ``[t_{k-1}, t_k]`` (from
``t0`` for k = 0); :func:`_finish_pre` adds the last segment, to ``t1``.
Depth = where the accumulated opacity first reaches 0.5 (``DEPTH_OPACITY``),
inf if never. State: :class:`CompositeState`.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ...jit import njit
from ..optics import composite, correct_opacity, power
from ._bspline import normal
from ._color import emission
from ._frame import FAR
from ._labelled import classify_sample
from ._pieces import Composite, LabelledComposite, Preintegrated, eager, finish, init, radius, shade, step, uses_normals
from ._ray import sample_at

__all__ = ["DEPTH_OPACITY", "lit", "CompositeState"]

DEPTH_OPACITY = 0.5


class CompositeState(NamedTuple):
    """What a composite ray carries from sample to sample."""

    red: float         #: accumulated premultiplied colour
    green: float
    blue: float
    alpha: float       #: accumulated opacity
    depth: float       #: where ``alpha`` first reached :data:`DEPTH_OPACITY` (``FAR``: not yet)
    prev_value: float  #: pre-integrated: the previous sample's value (table units)
    prev_t: float      #: pre-integrated: the previous sample's ray parameter


@njit(cache=True, fastmath=True, inline="always")
def lit(light, r, a, s, t, c, gradop):
    """Premultiplied sample ``c = (r, g, b, alpha)`` at ray parameter ``t`` (its colour the voxel's own in a
    colour volume, ``_color.emission``), modulated by the gradient opacity
    (when ``gradop``) and lit by the light tag's model."""
    x = r.oi + t * r.di
    y = r.oj + t * r.dj
    z = r.ok + t * r.dk
    cr, cg, cb, al = emission(a, s, x, y, z, c)
    gx = gy = gz = code = 0.0
    if uses_normals(light) or gradop:
        gx, gy, gz, code = normal(s.recon, a, x, y, z, s.nearest, uses_normals(light), gradop)
    if gradop:
        f = a.gradient_lut[min(int(code + 0.5), 127)]
        cr, cg, cb, al = cr * f, cg * f, cb * f, al * f
    if al > 0.0:
        fr, fg, fb, sr, sg, sb = shade(light, a, s, (gx, gy, gz), (-r.dx, -r.dy, -r.dz),
                                       (r.ox + t * r.dx, r.oy + t * r.dy, r.oz + t * r.dz))
        cr, cg, cb = cr * fr + al * sr, cg * fg + al * sg, cb * fb + al * sb
    return cr, cg, cb, al


@njit(cache=True, fastmath=True, inline="always")
def _corrected(c, seg, ds):
    """``c`` with its opacity corrected from length ``ds`` to ``seg`` (colour scaled alike)."""
    cr, cg, cb, al = c
    if al > 0.0 and seg != ds:
        a2 = correct_opacity(al, seg / ds)
        f = a2 / al
        return cr * f, cg * f, cb * f, a2
    return c


@njit(cache=True, fastmath=True, inline="always")
def _merged(c, span):
    """``c`` standing for ``span`` whole steps: opacity ``1 - (1 - alpha) ** span`` by repeated multiplication
    (``optics.power``; a call to ``pow`` in the loop cost 3-7 % of an adaptive frame), colour scaled alike."""
    cr, cg, cb, al = c
    if al > 0.0:
        a2 = 1.0 - power(1.0 - al, span) if al < 1.0 else 1.0
        f = a2 / al
        return cr * f, cg * f, cb * f, a2
    return c


@njit(cache=True, fastmath=True, inline="always")
def _accumulate(st, c, t, et):
    """Composite ``c`` under the state's colour; ``(state, done)``."""
    ar, ag, ab, aa, dep = st.red, st.green, st.blue, st.alpha, st.depth
    cr, cg, cb, al = c
    if al > 0.0:
        ar, ag, ab, aa = composite(ar, ag, ab, aa, cr, cg, cb, al)
        if dep == FAR and aa >= DEPTH_OPACITY:
            dep = t
    return CompositeState(ar, ag, ab, aa, dep, st.prev_value, st.prev_t), aa >= et


@init.register(Composite, LabelledComposite, Preintegrated)
@njit(cache=True, fastmath=True, inline="always")
def _init(light, r, a, s):
    return CompositeState(0.0, 0.0, 0.0, r.a0, FAR, 0.0, r.t0), 0, r.a0 >= s.early_termination, False


@njit(cache=True, fastmath=True, inline="always")
def _post(light, r, a, s, st, smp, c):
    """Composite the classified colour ``c`` of sample ``smp`` (``_pieces.Sample``: sample ``k`` at ``t``,
    standing for ``span`` grid steps from it: more than 1 only where adaptive sampling merges steps, ``_march``):
    ``(state, 0, done)``."""
    k, t, span = smp.k, smp.t, smp.span
    if k == 0 or k + span >= r.n:  # the end samples stand for less than a step (or a merged one's part)
        seg = (r.t1 if k + span >= r.n else t + (span - 0.5) * s.ds) - (r.t0 if k == 0 else t - 0.5 * s.ds)
        c = _corrected(c, seg, s.ds)
    elif span > 1:  # a merged sample inside the ray: ``span`` whole steps
        c = _merged(c, span)
    if c[3] > 0.0:
        c = lit(light, r, a, s, t, c, s.gradient_opacity)
    st, done = _accumulate(st, c, t, s.early_termination)
    return st, 0, done


@step.register(Composite)
@njit(cache=True, fastmath=True, inline="always")
def _step_post(light, r, a, s, st, smp):
    idx = np.uintp(smp.v + 0.5)  # v >= 0: the table spans the volume's whole range; unsigned: no wraparound code
    al = a.lut[idx, 3]
    return _post(light, r, a, s, st, smp, (a.lut[idx, 0] * al, a.lut[idx, 1] * al, a.lut[idx, 2] * al, al))


@step.register(LabelledComposite)
@njit(cache=True, fastmath=True, inline="always")
def _step_labelled(light, r, a, s, st, smp):
    t = smp.t
    c = classify_sample(a, s, r.oi + t * r.di, r.oj + t * r.dj, r.ok + t * r.dk, np.uintp(smp.v + 0.5))
    return _post(light, r, a, s, st, smp, c)


@njit(cache=True, fastmath=True, inline="always")
def _lookup_pre(pre, vf, vb, scale):
    n = pre.shape[0] - 1
    f = min(int(vf * scale + 0.5), n)
    b = min(int(vb * scale + 0.5), n)
    return pre[f, b, 0], pre[f, b, 1], pre[f, b, 2], pre[f, b, 3]


@step.register(Preintegrated)
@njit(cache=True, fastmath=True, inline="always")
def _step_pre(light, r, a, s, st, smp):
    k, t, v = smp.k, smp.t, smp.v
    vp, tp = st.prev_value, st.prev_t
    extra = 0
    if k == 0:
        vp, tp = v, r.t0
    elif not smp.have:
        tp = r.t0 + (k - 1 + r.jit) * s.ds
        vp = sample_at(r, a, s, tp)
        extra = 1
    seg = t - tp if (k == 0 or k == r.n - 1) else s.ds
    c = _corrected(_lookup_pre(a.preintegrated, vp, v, s.pre_scale), seg, s.ds)
    if c[3] > 0.0:
        c = lit(light, r, a, s, t, c, s.gradient_opacity)
    st, done = _accumulate(st, c, t, s.early_termination)
    return CompositeState(st.red, st.green, st.blue, st.alpha, st.depth, v, t), extra, done


@njit(cache=True, fastmath=True)
def _last_segment(light, r, a, s, st, have):
    """The pre-integrated segment from the last sample to the exit: ``(state, samples taken)``."""
    vp, tp = st.prev_value, st.prev_t
    taken = 0
    if not have:
        tp = min(r.t0 + (r.n - 1 + r.jit) * s.ds, r.t1)
        vp = sample_at(r, a, s, tp)
        taken += 1
    v = sample_at(r, a, s, r.t1)
    c = _lookup_pre(a.preintegrated, vp, v, s.pre_scale)
    if c[3] > 0.0:
        c = _corrected(lit(light, r, a, s, r.t1, c, False), r.t1 - tp, s.ds)
        st = _accumulate(st, c, r.t1, s.early_termination)[0]
    return st, taken + 1


@njit(cache=True, fastmath=True)
def _write(st, taken, pix, hdr):
    """The pixel's outputs: colour at most 1 (unclipped when ``hdr``: for a tone curve), opacity at most 1."""
    out, px, py = pix.out, pix.x, pix.y
    out.nsamp[py, px] = taken
    out.rgba[py, px, 0] = st.red if hdr else min(st.red, 1.0)
    out.rgba[py, px, 1] = st.green if hdr else min(st.green, 1.0)
    out.rgba[py, px, 2] = st.blue if hdr else min(st.blue, 1.0)
    out.rgba[py, px, 3] = min(st.alpha, 1.0)
    out.depth[py, px] = st.depth


@finish.register(Composite, LabelledComposite)
@njit(cache=True, fastmath=True)
def _finish_post(light, r, a, s, st, end, pix):
    _write(st, end.taken, pix, s.hdr)


@finish.register(Preintegrated)
@njit(cache=True, fastmath=True)
def _finish_pre(light, r, a, s, st, end, pix):
    taken = end.taken
    if st.alpha < s.early_termination and r.t1 - st.prev_t > 1e-6 * s.ds:
        st, extra = _last_segment(light, r, a, s, st, end.have)
        taken += extra
    _write(st, taken, pix, s.hdr)


@radius.register(Composite, LabelledComposite, Preintegrated)
@njit(cache=True, fastmath=True, inline="always")
def _radius(a, s, st, o, bk, bj, bi):
    return int(a.skip_flags[o, bk, bj, bi])


@eager.register(Composite, LabelledComposite)
@njit(cache=True, inline="always")
def _eager_yes():
    return True


@eager.register(Preintegrated)
@njit(cache=True, inline="always")
def _eager_no():
    return False
