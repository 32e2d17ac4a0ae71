"""The one marching loop: ``trace_pixel`` casts the ray of one pixel for every mode.

Arrays and scalars only, no allocation: the CPU driver (``_cpu``) calls it
from a ``prange`` loop and a CUDA kernel can call the same function.

Sampling. The ray's drawn interval ``[t0, t1]`` (``_geometry``) is sampled
at ``t_k = t0 + (k + j) ds``, ``k = 0 .. n-1``, with ``j`` in [0, 1) the
pixel's jitter (0 without jitter) and ``n`` the number of such points in
``[t0, t1]`` (at least 1). With jitter off, the first sample is at the exact
entry and, when the length is a whole number of steps, the last at the
exact exit.

Modes (the per-sample piece each mode plugs into the loop):

* composite: post-classified samples each stand for the part of
  ``[t0, t1]`` nearer to them than to their neighbours (``ds`` inside, less at
  the ends), opacity corrected to that length, so a ray's total length is
  exact whatever the step. Pre-integrated: sample ``k`` closes the segment
  ``[t_{k-1}, t_k]`` (from ``t0`` for k = 0; a last segment runs to ``t1``).
  Depth = where the accumulated opacity first reaches 0.5
  (``DEPTH_OPACITY``), inf if never.
* mip / minip: the largest / smallest sample; depth = where it was first met.
* average: mean of the samples taken; depth = the ray's entry ``t0``.
* isosurface: the first place the value rises to the threshold, found
  between the sample below and the sample at/above it by 4 regula-falsi
  steps; a ray whose entry is already inside shows the cut (cap) at ``t0``.

Empty-space skipping: when a sample falls in a block that cannot contribute
(composite: no visible value in the block's range; isosurface: threshold
outside it; mip: block max <= current max; minip: block min >= current min)
and so did the previous sample, the loop jumps to the first sample past the
block -- past the whole cube of empty blocks around it, for composite and
isosurface, whose block array holds the Chebyshev distance (in blocks) to
the nearest block that can contribute -- keeping the same sample grid, so
skipping changes no pixel.
"""

from __future__ import annotations

import math

from numba import njit

from ..optics import composite, correct_opacity
from ._geometry import primary_ray, ray_interval, to_index
from ._params import (
    I_BLOCK,
    I_GRADOP,
    I_JITTER,
    I_MODE,
    I_MODEL,
    I_NEAREST,
    I_NPLANES,
    I_PREINT,
    I_SEED,
    I_SHADED,
    I_SKIP,
    M_SCATTER,
    P_DS,
    P_ET,
    P_ISO,
    P_ISO_R,
    P_PRE_SCALE,
    P_VMIN,
    P_VSCALE,
)
from ._sample import jitter01, sample_normal, sample_value
from ._shade import shade

__all__ = ["trace_pixel", "MODE_CODES", "DEPTH_OPACITY", "FAR"]

COMPOSITE, MIP, MINIP, AVERAGE, ISOSURFACE = 0, 1, 2, 3, 4
MODE_CODES = {"composite": COMPOSITE, "mip": MIP, "minip": MINIP, "average": AVERAGE, "isosurface": ISOSURFACE}
DEPTH_OPACITY = 0.5
#: "infinitely far" inside the kernels, which are compiled with fastmath (no inf/NaN semantics);
#: the driver turns depth >= FAR into inf and value >= FAR into NaN.
FAR = 1e30


@njit(cache=True, fastmath=True)
def _skip_radius(mode, dist, bmin, bmax, vext):
    """How far a sample's block lets the ray skip: 0 = not skippable, r >= 1 = the cube of blocks within
    Chebyshev distance r - 1 of this one cannot contribute."""
    if mode == COMPOSITE or mode == ISOSURFACE:
        return dist
    if mode == MIP:
        return 1 if bmax <= vext else 0
    if mode == MINIP:
        return 1 if bmin >= vext else 0
    return 0


@njit(cache=True, fastmath=True)
def _box_exit(x, inv_d, b, radius, size):
    """Parameter distance along the index ray from coordinate x to the far side of blocks
    b - radius + 1 .. b + radius - 1 (one axis); ``inv_d`` = 1 / direction (0 when the direction is 0)."""
    if inv_d > 0.0:
        return ((b + radius) * size - x) * inv_d
    if inv_d < 0.0:
        return ((b - radius + 1) * size - x) * inv_d
    return FAR


@njit(cache=True, fastmath=True)
def _lookup_pre(pre, vf, vb, scale):
    n = pre.shape[0] - 1
    f = min(int(vf * scale + 0.5), n)
    b = min(int(vb * scale + 0.5), n)
    return pre[f, b, 0], pre[f, b, 1], pre[f, b, 2], pre[f, b, 3]


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


@njit(cache=True, fastmath=True, inline="always")
def trace_pixel(px, py, cam, geo, planes, vol, nrm, lut, pre, glut, bflag, bmin, bmax, lights, lvm, lvd, sig,
                prm, iprm, rgba, depth, value, nsamp):
    """Cast the ray of pixel (px, py) and write ``rgba[py, px]``, ``depth``, ``value``, ``nsamp`` there.

    Parameters are the packed arrays built by ``_cpu.render_cpu``: camera,
    geometry, clip planes (n, 6), normalized volume ``[z, y, x]`` float32,
    packed normals ``[z, y, x, 4]`` int16, colour table (NLUT, 4),
    pre-integrated table (NPRE, NPRE, 4), gradient table (128,), block
    skip distances (uint8) / min / max ``[bz, by, bx]``, lights (n, NLCOL), illumination-volume
    meta rows / buffer and optical-depth table (``_lightvol``), float and integer parameters
    (``_params``). Shading (every model) goes through ``_shade.shade``.
    """
    rgba[py, px, 0] = 0.0
    rgba[py, px, 1] = 0.0
    rgba[py, px, 2] = 0.0
    rgba[py, px, 3] = 0.0
    depth[py, px] = FAR
    value[py, px] = FAR
    nsamp[py, px] = 0
    ox, oy, oz, dx, dy, dz = primary_ray(cam, px, py)
    t0, t1 = ray_interval(cam, geo, planes, iprm[I_NPLANES], ox, oy, oz, dx, dy, dz)
    if not t1 >= t0:
        return
    oi, oj, ok = to_index(geo, ox, oy, oz, 1.0)
    di, dj, dk = to_index(geo, dx, dy, dz, 0.0)
    inv_di = 1.0 / di if di != 0.0 else 0.0
    inv_dj = 1.0 / dj if dj != 0.0 else 0.0
    inv_dk = 1.0 / dk if dk != 0.0 else 0.0
    mode = iprm[I_MODE]
    nearest = iprm[I_NEAREST] != 0
    skip = iprm[I_SKIP] != 0
    preint = iprm[I_PREINT] != 0
    gradop = iprm[I_GRADOP] != 0
    shaded = iprm[I_SHADED] != 0
    need_normal = gradop or (shaded and iprm[I_MODEL] != M_SCATTER)
    bsize = iprm[I_BLOCK]
    inv_b = 1.0 / bsize
    gz, gy, gx = bflag.shape
    ds = prm[P_DS]
    et = prm[P_ET]
    iso = prm[P_ISO]
    jit = jitter01(px, py, iprm[I_SEED]) if iprm[I_JITTER] != 0 else 0.0
    n = int(math.floor((t1 - t0) / ds - jit + 1e-4)) + 1
    if n < 1:
        n = 1

    acc_r = 0.0
    acc_g = 0.0
    acc_b = 0.0
    acc_a = 0.0
    dep = FAR
    vext = -FAR if mode == MIP else FAR
    vsum = 0.0
    cnt = 0
    taken = 0
    done = False
    vp = 0.0  # previous sample value and position
    tp = t0
    have_prev = False
    prev_skip = False
    # jump at the first sample in a skippable block when no neighbouring sample is needed to classify
    # (post-classified composite, isosurface); otherwise wait for a second one (pre-integration, projections)
    eager = (mode == COMPOSITE and not preint) or mode == ISOSURFACE
    if mode == ISOSURFACE:
        vp = sample_value(vol, oi + t0 * di, oj + t0 * dj, ok + t0 * dk, nearest)
        taken += 1
        have_prev = True
        if vp >= iso:
            dep = t0
            done = True
    k = 0
    t = t0
    while k < n and not done:
        t = min(t0 + (k + jit) * ds, t1)
        x = oi + t * di
        y = oj + t * dj
        z = ok + t * dk
        if skip:
            bi = min(max(int(x * inv_b), 0), gx - 1)
            bj = min(max(int(y * inv_b), 0), gy - 1)
            bk = min(max(int(z * inv_b), 0), gz - 1)
            if eager:  # composite / isosurface: the block's skip distance decides alone
                rad = int(bflag[bk, bj, bi])
            else:
                rad = int(_skip_radius(mode, bflag[bk, bj, bi], bmin[bk, bj, bi], bmax[bk, bj, bi], vext))
            if rad > 0:
                if prev_skip or eager:
                    dt = min(_box_exit(x, inv_di, bi, rad, bsize), _box_exit(y, inv_dj, bj, rad, bsize),
                             _box_exit(z, inv_dk, bk, rad, bsize))
                    kn = int(math.ceil((t + dt - t0) / ds - jit))
                    k = max(kn, k + 1)
                    have_prev = False
                    continue
                prev_skip = True
            else:
                prev_skip = False
        v = sample_value(vol, x, y, z, nearest)
        taken += 1
        if mode == COMPOSITE:
            if preint:
                if k == 0:
                    vp = v
                    tp = t0
                elif not have_prev:
                    tp = t0 + (k - 1 + jit) * ds
                    vp = sample_value(vol, oi + tp * di, oj + tp * dj, ok + tp * dk, nearest)
                    taken += 1
                cr, cg, cb, a = _lookup_pre(pre, vp, v, prm[P_PRE_SCALE])
                seg = t - tp if (k == 0 or k == n - 1) else ds
            else:
                idx = int(v + 0.5)
                a = lut[idx, 3]
                cr = lut[idx, 0] * a
                cg = lut[idx, 1] * a
                cb = lut[idx, 2] * a
                seg = ds
                if k == 0 or k == n - 1:
                    seg = (t1 if k == n - 1 else t + 0.5 * ds) - (t0 if k == 0 else t - 0.5 * ds)
            if a > 0.0 and seg != ds:
                a2 = correct_opacity(a, seg / ds)
                s = a2 / a
                cr *= s
                cg *= s
                cb *= s
                a = a2
            if a > 0.0 and (shaded or gradop):
                ngx = ngy = ngz = code = 0.0
                if need_normal:
                    ngx, ngy, ngz, code = sample_normal(nrm, x, y, z, nearest)
                if gradop:
                    f = glut[min(int(code + 0.5), 127)]
                    a *= f
                    cr *= f
                    cg *= f
                    cb *= f
                if shaded and a > 0.0:
                    fr, fg, fb, sr, sg, sb = shade(ngx, ngy, ngz, -dx, -dy, -dz, ox + t * dx, oy + t * dy, oz + t * dz,
                                                  vol, geo, planes, lights, lvm, lvd, sig, prm, iprm)
                    cr = cr * fr + a * sr
                    cg = cg * fg + a * sg
                    cb = cb * fb + a * sb
            if a > 0.0:
                acc_r, acc_g, acc_b, acc_a = composite(acc_r, acc_g, acc_b, acc_a, cr, cg, cb, a)
                if dep == FAR and acc_a >= DEPTH_OPACITY:
                    dep = t
                if acc_a >= et:
                    done = True
        elif mode == MIP:
            if v > vext:
                vext = v
                dep = t
        elif mode == MINIP:
            if v < vext:
                vext = v
                dep = t
        elif mode == AVERAGE:
            vsum += v
            cnt += 1
        else:  # ISOSURFACE
            if v >= iso:
                if not have_prev:
                    tp = max(t - ds, t0)
                    vp = sample_value(vol, oi + tp * di, oj + tp * dj, ok + tp * dk, nearest)
                    taken += 1
                dep = t if vp >= iso else iso_refine(vol, nearest, iso, tp, vp, t, v, oi, oj, ok, di, dj, dk)
                done = True
        vp = v
        tp = t
        have_prev = True
        k += 1

    if mode == COMPOSITE and preint and not done and t1 - tp > 1e-6 * ds:
        # the last segment, from the last sample to the exit
        if not have_prev:
            tp = min(t0 + (n - 1 + jit) * ds, t1)
            vp = sample_value(vol, oi + tp * di, oj + tp * dj, ok + tp * dk, nearest)
            taken += 1
        v = sample_value(vol, oi + t1 * di, oj + t1 * dj, ok + t1 * dk, nearest)
        taken += 1
        cr, cg, cb, a = _lookup_pre(pre, vp, v, prm[P_PRE_SCALE])
        if a > 0.0:
            a2 = correct_opacity(a, (t1 - tp) / ds)
            s = a2 / a
            if shaded:
                x = oi + t1 * di
                y = oj + t1 * dj
                z = ok + t1 * dk
                ngx = ngy = ngz = code = 0.0
                if need_normal:
                    ngx, ngy, ngz, code = sample_normal(nrm, x, y, z, nearest)
                fr, fg, fb, sr, sg, sb = shade(ngx, ngy, ngz, -dx, -dy, -dz, ox + t1 * dx, oy + t1 * dy,
                                              oz + t1 * dz, vol, geo, planes, lights, lvm, lvd, sig, prm, iprm)
                cr = cr * fr + a * sr
                cg = cg * fg + a * sg
                cb = cb * fb + a * sb
            acc_r, acc_g, acc_b, acc_a = composite(acc_r, acc_g, acc_b, acc_a, cr * s, cg * s, cb * s, a2)
            if dep == FAR and acc_a >= DEPTH_OPACITY:
                dep = t1

    nsamp[py, px] = taken
    if mode == COMPOSITE:
        rgba[py, px, 0] = min(acc_r, 1.0)
        rgba[py, px, 1] = min(acc_g, 1.0)
        rgba[py, px, 2] = min(acc_b, 1.0)
        rgba[py, px, 3] = min(acc_a, 1.0)
        depth[py, px] = dep
        return
    if mode == ISOSURFACE:
        if dep < FAR:
            r = prm[P_ISO_R]
            g = prm[P_ISO_R + 1]
            b = prm[P_ISO_R + 2]
            if shaded:
                x = oi + dep * di
                y = oj + dep * dj
                z = ok + dep * dk
                ngx, ngy, ngz, code = sample_normal(nrm, x, y, z, nearest)
                fr, fg, fb, sr, sg, sb = shade(ngx, ngy, ngz, -dx, -dy, -dz, ox + dep * dx, oy + dep * dy,
                                              oz + dep * dz, vol, geo, planes, lights, lvm, lvd, sig, prm, iprm)
                r = r * fr + sr
                g = g * fg + sg
                b = b * fb + sb
            rgba[py, px, 0] = min(r, 1.0)
            rgba[py, px, 1] = min(g, 1.0)
            rgba[py, px, 2] = min(b, 1.0)
            rgba[py, px, 3] = 1.0
            depth[py, px] = dep
        return
    # projections: the value's colour and opacity from the (uncorrected) table
    if mode == AVERAGE:
        if cnt == 0:
            return
        vext = vsum / cnt
        dep = t0
    elif taken == 0:
        return
    idx = min(max(int(vext + 0.5), 0), lut.shape[0] - 1)
    a = lut[idx, 3]
    rgba[py, px, 0] = lut[idx, 0] * a
    rgba[py, px, 1] = lut[idx, 1] * a
    rgba[py, px, 2] = lut[idx, 2] * a
    rgba[py, px, 3] = a
    depth[py, px] = dep
    value[py, px] = prm[P_VMIN] + vext * prm[P_VSCALE]
