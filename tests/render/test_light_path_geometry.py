"""The light paths' geometry against what it stands for: the drawn region's interval of a short path
(``_geometry.segment_interval``) and the lattice node a position reads (``_lightvol.lattice_site``)."""

from __future__ import annotations

import numpy as np
import pytest

from volumen.core import Clipping, ClipPlane, Volume
from volumen.render.raycast import _params as lv
from volumen.render.raycast._geometry import pack_geometry, pack_planes, region_interval, segment_interval
from volumen.render.raycast._lightvol import lattice_site, plan_lattice


def _oblique_volume(shape=(30, 34, 40)):
    aff = np.array([[0.8, 0.1, 0.0, -12.0], [0.0, 0.7, 0.2, 5.0], [0.1, 0.0, 1.3, 30.0], [0, 0, 0, 1.0]])
    return Volume(np.zeros(shape, np.int16), affine=aff)


@pytest.mark.parametrize("clipping", [
    Clipping(),
    Clipping(crop=(4, 30, 3, 25, 2, 20)),
    Clipping(crop=(-15, 20, 0, 30, 28, 70), crop_space="world",
             planes=(ClipPlane(point=(0, 25, 40), normal=(0.3, -1, 0.2)),
                     ClipPlane(point=(-3, 0, 0), normal=(1, 1, 1)))),
])
def test_a_short_path_gets_the_region_interval_and_inside_the_whole_path(clipping):
    """Random short paths (a few mm, as the near march's): where both ends lie in the region the interval is the
    whole path, exactly; elsewhere the slab and plane interval. Either way the region interval to 1e-12 mm."""
    vol = _oblique_volume()
    geo, planes = pack_geometry(vol, clipping), pack_planes(clipping)
    n = len(clipping.planes)
    rng = np.random.default_rng(3)
    aff = np.asarray(vol.affine, float)
    whole = inside = 0
    for _ in range(3000):
        o = aff[:3, :3] @ rng.uniform(-4, 44, 3) + aff[:3, 3]
        d = rng.normal(size=3)
        d /= np.linalg.norm(d)
        t1 = rng.uniform(0.5, 8.0)
        want = region_interval(geo, planes, n, tuple(o), tuple(d), 0.0, t1)
        got = segment_interval(geo, planes, n, tuple(o), tuple(d), t1)
        if want[1] >= want[0]:
            np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)
            whole += want == (0.0, t1) or np.allclose(want, (0.0, t1), rtol=0, atol=1e-12)
            inside += got == (0.0, t1)
        else:
            assert got[1] < got[0]
    assert inside > 100 and whole >= inside  # the inner paths took the short way, and the region agrees


def _ray_point(m, v, u, i):
    """Index position (x, y, z) where lattice ray (v, u) crosses its slice i (the plan's geometry: from the light
    P through (kfar, ov + v h, ou + u h))."""
    pa, pb, pc, kfar, k0, h = (m[j] for j in (lv.LV_PA, lv.LV_PB, lv.LV_PC, lv.LV_KFAR, lv.LV_K0, lv.LV_H))
    s = (k0 + i - pa) / (kfar - pa)
    p = np.zeros(3)  # data axes (z, y, x)
    p[int(m[lv.LV_AXA])] = k0 + i
    p[int(m[lv.LV_AXB])] = pb + s * (m[lv.LV_OV] + v * h - pb)
    p[int(m[lv.LV_AXC])] = pc + s * (m[lv.LV_OU] + u * h - pc)
    return p[2], p[1], p[0]


@pytest.mark.parametrize("light", [(-30.0, 12.0, 20.0), (50.0, 60.0, -25.0), (14.0, -40.0, 70.0)])
def test_a_position_on_a_lattice_ray_reads_that_ray(light):
    """A point where lattice ray (v, u) crosses slice i reads node (v, u) of slice i: its lower node and fractions
    add up to (v, u) within 1e-9, for
    lights on either side of each sweep axis."""
    shape = (30, 34, 40)
    m = plan_lattice(np.array(light), np.zeros(3), np.array([39.0, 33.0, 29.0]), shape, 2.0)
    nk, nv, nu = (int(m[j]) for j in (lv.LV_NK, lv.LV_NV, lv.LV_NU))
    rng = np.random.default_rng(8)
    for i, v, u in zip(rng.integers(0, nk - 1, 200), rng.integers(1, nv - 2, 200), rng.integers(1, nu - 2, 200),
                       strict=True):
        x, y, z = _ray_point(m, v, u, i)
        i0, fu0, fv0, _, _, _, w, nrow = lattice_site(m[None, :], 0, x, y, z)
        assert nrow == nu and w == pytest.approx(0.0, abs=1e-9)
        vv, uu = divmod(i0 - i * nv * nu, nu)  # node (v, u) at fraction 0, or its lower neighbour at 1
        assert vv + fv0 == pytest.approx(v, abs=1e-9) and uu + fu0 == pytest.approx(u, abs=1e-9)
