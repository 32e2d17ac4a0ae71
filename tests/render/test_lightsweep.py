"""The CPU lattice sweep (``raycast._lightsweep._sweep``) against its own pieces, ray by ray: a slice where the
ray's optical depth did not change takes the slice before's transmittance (no ``exp``), and that changes no
stored value."""

from __future__ import annotations

import numpy as np

from volumen.core import Camera, Scene, Shading, TransferFunction
from volumen.data import phantom
from volumen.render.raycast._lightsweep import (
    LatticeRay,
    lattice_frame,
    lattice_offsets,
    lattice_ray,
    lattice_slice,
    lattice_step,
    lattice_transmittance_of,
)
from volumen.render.raycast._medium import Medium
from volumen.render.raycast._pack import pack_frame
from volumen.render.raycast._params import LATTICE, LV_AXA, LV_AXB, LV_AXC, LV_KIND, LV_NK, LV_NU, LV_NV, LV_OFF


def _one_ray(med, aff, geo, meta, v, u, kext, ds0):
    """The transmittances lattice ray ``(v, u)`` stores on its slices, stepped here one slice at a time."""
    pa, pb, pc, da, k0, nk, dsl, fwd = lattice_frame(meta)
    db, dc = lattice_offsets(meta, v, u)
    _, _, t0, t1, length, sub = lattice_ray(aff, geo, np.zeros((1, 6)), 0, meta, v, u)
    acc, sp = 0.0, -1.0
    out = np.empty(nk, np.float32)
    for st in range(nk):
        i, k, s = lattice_slice(st, nk, k0, pa, dsl, fwd)
        acc, sp = lattice_step(med, k, s, dsl, LatticeRay(pa, pb, pc, da, db, dc, t0, t1, length, sub), acc, sp)
        out[i] = lattice_transmittance_of(acc, kext / ds0)
    return out


def test_the_sweep_stores_what_each_ray_gives_on_its_own():
    vol = phantom("head", size=(40, 44, 44))
    tf = TransferFunction.preset("ct-bone")
    spot = Camera.orbit(vol, azimuth=40, elevation=35).position
    from volumen.core import Light

    scene = Scene(volume=vol, transfer=tf, shading=Shading(mode="shadows"),
                  lights=(Light(kind="point", position=spot),))
    f = pack_frame(scene, Camera.orbit(vol), (8, 8))
    a, s = f.arrays, f.settings
    meta = a.light_meta[0]
    assert meta[LV_KIND] == LATTICE
    nk, nv, nu = (int(meta[i]) for i in (LV_NK, LV_NV, LV_NU))
    swept = a.light_data[int(meta[LV_OFF]):int(meta[LV_OFF]) + nk * nv * nu].reshape(nk, nv, nu)
    axes = tuple(int(meta[i]) for i in (LV_AXA, LV_AXB, LV_AXC))  # the sweep reads the volume in its axes' order
    med = Medium(np.transpose(a.vol, axes), a.extinction, s.sample_offset, s.sample_scale,
                 np.transpose(a.label_map, axes), a.label_lut, a.lut, 1.0, 0, s.recon)
    aff = np.ascontiguousarray(np.asarray(vol.affine, float)[:3, :4])
    rng = np.random.default_rng(5)
    shadowed = 0
    for v, u in zip(rng.integers(0, nv, 60), rng.integers(0, nu, 60), strict=True):
        want = _one_ray(med, aff, a.geo, meta, int(v), int(u), s.extinction_scale, s.ds0)
        np.testing.assert_array_equal(swept[:, v, u], want)
        shadowed += bool((want < 0.5).any())
    assert shadowed >= 10  # rays that cross the skull, and keep its shadow over the slices past it
