"""The illumination-volume sweep: per-light-ray pieces shared by the CPU sweep and the CUDA kernel.

See :mod:`._lightvol` for the geometry of a light's lattice of rays (what is
stored where). Each piece here handles one ray at one slice, so the CPU
driver (:func:`_sweep`, rows of rays per slice in parallel) and the CUDA
kernel (one ray per thread) run the same code.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np

from ...jit import njit, run_parts
from ._geometry import region_interval
from ._medium import Medium, depth_at
from ._params import (
    LV_AXA,
    LV_AXB,
    LV_AXC,
    LV_H,
    LV_K0,
    LV_KFAR,
    LV_NK,
    LV_NU,
    LV_NV,
    LV_OU,
    LV_OV,
    LV_PA,
    LV_PB,
    LV_PC,
    MAX_STEP,
)
from ._pieces import ScanOnly, Trilinear, labelled

__all__ = ["build_lattice", "LatticeRay", "lattice_frame", "lattice_offsets", "lattice_ray", "lattice_slice",
           "lattice_step", "lattice_transmittance_of", "sweep_medium"]


@njit(cache=True, fastmath=True)
def _to_world(aff, axa, axb, axc, ca, cb, cc, w):
    x = ca if axa == 2 else (cb if axb == 2 else cc)
    y = ca if axa == 1 else (cb if axb == 1 else cc)
    z = ca if axa == 0 else (cb if axb == 0 else cc)
    return (aff[0, 0] * x + aff[0, 1] * y + aff[0, 2] * z + aff[0, 3] * w,
            aff[1, 0] * x + aff[1, 1] * y + aff[1, 2] * z + aff[1, 3] * w,
            aff[2, 0] * x + aff[2, 1] * y + aff[2, 2] * z + aff[2, 3] * w)


@njit(cache=True, fastmath=True, inline="always")
def _depth(med, ca, cb, cc):
    """Optical depth per reference step at (a, b, c) = (ca, cb, cc) (``med``'s axes ordered (a, b, c))."""
    return depth_at(med, cc, cb, ca)[0]


@njit(cache=True, fastmath=True, inline="always")
def _depth_slice(med, k, cb, cc):
    """``_depth`` at a point of slice ``k`` (integer): bilinear within the slice, the same value trilinear gives
    (read as such without labels; with labels, :func:`._medium.depth_at` classifies it)."""
    if labelled(med.labels):
        return _depth(med, np.float64(k), cb, cc)
    volt, sig = med.vol, med.extinction
    nb = volt.shape[1]
    nc = volt.shape[2]
    if cb <= 0.0:
        j0, j1, fb = 0, 0, 0.0
    elif cb >= nb - 1:
        j0, j1, fb = nb - 1, nb - 1, 0.0
    else:
        j0 = int(cb)
        j1, fb = j0 + 1, cb - j0
    if cc <= 0.0:
        i0, i1, fc = 0, 0, 0.0
    elif cc >= nc - 1:
        i0, i1, fc = nc - 1, nc - 1, 0.0
    else:
        i0 = int(cc)
        i1, fc = i0 + 1, cc - i0
    r0 = volt[k, j0, i0] + fc * (volt[k, j0, i1] - volt[k, j0, i0])
    r1 = volt[k, j1, i0] + fc * (volt[k, j1, i1] - volt[k, j1, i0])
    v = (r0 + fb * (r1 - r0) - med.sample_offset) * med.sample_scale
    return sig[min(max(int(v + 0.5), 0), sig.shape[0] - 1)]


@njit(cache=True, fastmath=True)
def lattice_frame(meta):
    """The sweep constants of one lattice: ``(pa, pb, pc, da, k0, nk, dsl, fwd)``.

    ``P = (pa, pb, pc)`` is the light in index coordinates along the sweep
    axes (a, b, c), ``da`` the distance along ``a`` from the light to the far
    slice, ``k0`` the first slice, ``nk`` the number of slices, ``dsl`` the
    ray parameter ``s`` between two slices and ``fwd`` whether the light is on
    the low-index side (slices swept in increasing order).
    """
    pa = meta[LV_PA]
    k0 = int(meta[LV_K0])
    da = meta[LV_KFAR] - pa
    return pa, meta[LV_PB], meta[LV_PC], da, k0, int(meta[LV_NK]), 1.0 / abs(da), pa < k0


@njit(cache=True, fastmath=True, inline="always")
def lattice_offsets(meta, v, u):
    """``(db, dc)``: the direction of lattice ray ``(v, u)`` along the b and c axes (index units, from the
    light to its node on the far slice)."""
    return meta[LV_OV] + v * meta[LV_H] - meta[LV_PB], meta[LV_OU] + u * meta[LV_H] - meta[LV_PC]


@njit(cache=True, fastmath=True)
def lattice_ray(aff, geo, planes, nplanes, meta, v, u):
    """Lattice ray ``(v, u)``: ``(db, dc, t0, t1, length, sub)``.

    ``(da, db, dc)`` is its direction in index coordinates along (a, b, c)
    (from the light to its node on the far slice), ``[t0, t1]`` its interval
    in ``s`` inside the drawn region (empty when t1 < t0), ``length`` its
    length in mm per unit ``s`` and ``sub`` the number of steps it takes between two slices (more than one
    where it crosses them so obliquely that a step would exceed ``MAX_STEP`` index units).
    """
    axa = int(meta[LV_AXA])
    axb = int(meta[LV_AXB])
    axc = int(meta[LV_AXC])
    pa, pb, pc, da, k0, nk, dsl, fwd = lattice_frame(meta)
    db, dc = lattice_offsets(meta, v, u)
    ox, oy, oz = _to_world(aff, axa, axb, axc, pa, pb, pc, 1.0)
    dx, dy, dz = _to_world(aff, axa, axb, axc, da, db, dc, 0.0)
    t0, t1 = region_interval(geo, planes, nplanes, (ox, oy, oz), (dx, dy, dz), 0.0, 2.0)
    sub = int(math.ceil(math.sqrt(da * da + db * db + dc * dc) * dsl / MAX_STEP))
    return db, dc, t0, t1, math.sqrt(dx * dx + dy * dy + dz * dz), sub


@njit(cache=True, fastmath=True, inline="always")
def lattice_slice(st, nk, k0, pa, dsl, fwd):
    """Sweep step ``st`` (0 = the slice nearest the light): ``(i, k, s)``: index ``i`` in the lattice, slice
    ``k`` of the volume, and the ray parameter ``s`` there."""
    i = st if fwd else nk - 1 - st
    k = k0 + i
    s = (k - pa) * dsl if fwd else (pa - k) * dsl
    return i, k, s


class LatticeRay(NamedTuple):
    """One lattice ray as :func:`lattice_step` carries it: ``p + s d`` in index coordinates along the lattice's
    axes (a, b, c), from the light (``s = 0``) to its node on the far slice (``s = 1``)."""

    pa: float      #: the light's position along a, b, c (:func:`lattice_frame`)
    pb: float
    pc: float
    da: float      #: the direction along a, b, c (:func:`lattice_frame`, :func:`lattice_offsets`)
    db: float
    dc: float
    t0: float      #: its interval in ``s`` inside the drawn region (empty when t1 < t0; :func:`lattice_ray`)
    t1: float
    length: float  #: its length in mm per unit ``s``
    sub: int       #: steps between two slices (:func:`lattice_ray`'s ``sub``)


@njit(cache=True, fastmath=True, inline="always")
def lattice_step(med, k, s, dsl, ray, acc, sp):
    """Carry lattice ray ``ray`` (a :class:`LatticeRay`) across slice ``k`` (at ``s``, ``dsl`` past the slice
    before) through the medium ``med`` (:func:`sweep_medium`) in ``ray.sub`` steps: returns its new ``(acc, sp)``.

    ``acc`` is the ray's optical depth so far (reference-step units x mm),
    ``sp`` its last sample (-1 before the region, -2 after it); the
    transmittance stored at the slice is :func:`lattice_transmittance_of`.
    """
    pa, pb, pc, da, db, dc = ray.pa, ray.pb, ray.pc, ray.da, ray.db, ray.dc
    t0, t1, length, m = ray.t0, ray.t1, ray.length, ray.sub
    if t1 >= t0 and s >= t0 and s <= t1:
        sg = _depth_slice(med, k, pb + db * s, pc + dc * s)
        if sp < 0.0:  # entering: the partial segment from the region's boundary
            acc += sg * (s - max(t0, s - dsl)) * length
        else:
            if m <= 1:
                acc += 0.5 * (sp + sg) * dsl * length
            else:
                sub = dsl / m
                q = sp
                for j in range(1, m):
                    sj = s - dsl + j * sub
                    r = _depth(med, pa + da * sj, pb + db * sj, pc + dc * sj)
                    acc += 0.5 * (q + r) * sub * length
                    q = r
                acc += 0.5 * (q + sg) * sub * length
        return acc, sg
    if sp >= 0.0 and s > t1:  # leaving: the partial segment to the boundary
        return acc + sp * (t1 - (s - dsl)) * length, -2.0
    return acc, sp


@njit(cache=True, fastmath=True, inline="always")
def lattice_transmittance_of(acc, scale):
    """Transmittance ``exp(-scale * acc)`` of an accumulated optical depth (``scale = kext / ds0``)."""
    return math.exp(-scale * acc) if acc > 0.0 else 1.0


class Sweep(NamedTuple):
    """What a lattice sweep reads (the CPU driver and the CUDA kernel take it whole)."""

    volt: Any      #: the samples with their axes ordered (a, b, c), read as ``_medium.depth_at`` does
    extinction: Any  #: optical depth per reference step of each table entry
    aff: Any       #: voxel -> world affine rows (3, 4)
    geo: Any       #: packed region (``_geometry``)
    planes: Any    #: clip planes (n, 6)
    meta: Any      #: the light's meta row (``_params``)
    nplanes: int
    ds0: float     #: reference step, mm
    extinction_scale: float  #: extinction scale
    sample_offset: float  #: samples -> table units: (v - sample_offset) * sample_scale
    sample_scale: float
    labt: Any      #: label map with its axes ordered (a, b, c) (``_medium.Medium.label_map``)
    label_lut: Any  #: label table, colour table, ``lscale``, ``nlabels``: as in ``_medium.Medium``
    lut: Any
    lscale: float
    nlabels: int
    recon: Any = Trilinear()  #: reconstruction tag (``_medium.Medium.recon``)
    labels: Any = ScanOnly()  #: label tag (``_medium.Medium.labels``)

    @classmethod
    def of(cls, med, axes, aff, geo, planes, meta, nplanes, ds0, kext):
        """The sweep of lattice ``meta`` through the (host or device) medium ``med`` (``_medium.Medium``, axes
        [z, y, x]), given ``permute(array, axes)`` views of its volume and label map in ``axes``."""
        volt, labt = axes(med.vol), axes(med.label_map)
        return cls(volt, med.extinction, aff, geo, planes, meta, int(nplanes), float(ds0), float(kext),
                   float(med.sample_offset), float(med.sample_scale), labt, med.label_lut, med.lut, float(med.lscale),
                   int(med.nlabels), med.recon, med.labels)


@njit(cache=True, fastmath=True, inline="always")
def sweep_medium(sw):
    """The :class:`._medium.Medium` a sweep reads."""
    return Medium(sw.volt, sw.extinction, sw.sample_offset, sw.sample_scale, sw.labt, sw.label_lut, sw.lut, sw.lscale,
                  sw.nlabels, sw.recon, sw.labels)


@njit(cache=True, fastmath=True, nogil=True, _nrt=False)
def _sweep(part, parts, sw, work, out):
    """Fill ``out[i, v, u]`` (slice ``k0 + i``) with the transmittance along lattice ray (v, u), for the rows
    of part ``part`` of ``parts`` (contiguous) (``volumen.jit.run_parts``).

    The work arrays ``work[0..5]`` (nv, nu) hold each ray's region interval in
    ``s``, its optical depth so far, its last sample (-1 before the region, -2
    after it), its length in mm per unit ``s`` and its steps between slices. Each row of rays (fixed v) is
    swept slice by slice (the per-ray pieces are shared with the CUDA sweep). Where a ray's optical depth did not
    change across a slice (transparent tissue), the slice takes the transmittance of the slice before instead of
    another ``exp``: the same value. And each ray's steps between slices (``lattice_ray``'s ``sub``, a square root
    and a division) are worked out once, not at every slice. Whole-abdomen CT, 366 x 303 x 336, ``ct-bone``, one
    light moved each frame: the sweep took 262 ms, 225 with the first, 195 with both (the same stored values).
    """
    nk, nv, nu = out.shape
    pa, pb, pc, da, k0, _, dsl, fwd = lattice_frame(sw.meta)
    scale = sw.extinction_scale / sw.ds0
    wt0, wt1, wacc, wsp, wlen, wsub = work
    med = sweep_medium(sw)
    for v in range(part * nv // parts, (part + 1) * nv // parts):
        for u in range(nu):
            _, _, t0, t1, length, sub = lattice_ray(sw.aff, sw.geo, sw.planes, sw.nplanes, sw.meta, v, u)
            wt0[v, u] = t0
            wt1[v, u] = t1
            wacc[v, u] = 0.0
            wsp[v, u] = -1.0
            wlen[v, u] = length
            wsub[v, u] = sub
        for st in range(nk):
            i, k, s = lattice_slice(st, nk, k0, pa, dsl, fwd)
            prev = i - 1 if fwd else i + 1  # the slice swept before this one
            for u in range(nu):
                db, dc = lattice_offsets(sw.meta, v, u)
                before = wacc[v, u]
                ray = LatticeRay(pa, pb, pc, da, db, dc, wt0[v, u], wt1[v, u], wlen[v, u], int(wsub[v, u]))
                acc, sp = lattice_step(med, k, s, dsl, ray, before, wsp[v, u])
                wacc[v, u] = acc
                wsp[v, u] = sp
                # the same optical depth as at the slice before (a stretch of transparent tissue): its transmittance
                out[i, v, u] = out[prev, v, u] if st > 0 and acc == before else lattice_transmittance_of(acc, scale)


def build_lattice(med, affine, geo, planes, nplanes, meta, ds0: float, kext: float, out=None) -> np.ndarray:
    """Sweep one light's lattice: float32 ``(nk, nv, nu)`` transmittances (into ``out`` when given).

    ``med`` is the medium (``_medium.Medium``: the volume ``[z, y, x]`` and its optical depth, or its label-aware
    classification), ``affine`` the (4, 4) voxel -> world
    matrix, ``geo``/``planes`` the packed region, ``ds0`` the reference step
    (mm), ``kext`` the extinction scale.
    """
    nk, nv, nu = (int(meta[i]) for i in (LV_NK, LV_NV, LV_NU))
    axes = tuple(int(meta[i]) for i in (LV_AXA, LV_AXB, LV_AXC))
    if out is None:
        out = np.empty((nk, nv, nu), np.float32)
    work = tuple(np.empty((nv, nu), np.float64) for _ in range(6))
    sw = Sweep.of(med, lambda x: np.transpose(x, axes), np.ascontiguousarray(np.asarray(affine, float)[:3, :4]),
                  geo, planes, np.asarray(meta, np.float64), nplanes, ds0, kext)
    run_parts(_sweep, nv, sw, work, out)
    return out
