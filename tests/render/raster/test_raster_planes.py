"""Plane distributions and plane-box polygons (numpy only, no OpenGL needed)."""

from __future__ import annotations

import numpy as np
import pytest

from volumen.render.raster import ADAPTIVE, slab_boundaries, slice_polygons
from volumen.render.raster._planes import box_corners


@pytest.mark.parametrize("mode", ADAPTIVE)
def test_slabs_tile_the_depth_range(mode):
    b = slab_boundaries(mode, 2.0, 150.0, ds0=1.0, spv=1.0, diagonal=160.0)
    assert b[0] == 2.0 and b[-1] == pytest.approx(150.0) and np.all(np.diff(b) > 0)


def test_distributions_put_planes_where_the_source_says():
    z0, z1, d = 0.0, 120.0, 200.0
    kw = dict(ds0=1.0, spv=1.0, diagonal=d)

    def mid(b):
        return 0.5 * (b[1:] + b[:-1])

    uni = slab_boundaries("uniform", z0, z1, **kw)
    assert len(uni) - 1 == 120 and np.allclose(np.diff(uni), 1.0)
    nq = mid(slab_boundaries("near-quarter", z0, z1, **kw))
    assert len(nq) == 120 and np.sum(nq < 30.0) == 80              # 2/3 within a quarter of near-far
    dq = mid(slab_boundaries("diagonal-quarter", z0, z1, **kw))
    assert len(dq) == 120 and np.sum(dq < 50.0) == 80              # 2/3 within a quarter of the diagonal
    two = slab_boundaries("two-per-voxel", z0, z1, **kw)
    assert np.allclose(np.diff(two), 0.5)
    tt = slab_boundaries("two-then-one", z0, z1, **kw)
    g = np.diff(tt)
    assert np.allclose(g[mid(tt) < 50], 0.5) and np.allclose(g[mid(tt) > 50], 1.0)
    with pytest.raises(ValueError, match="uniform"):
        slab_boundaries("random", z0, z1, **kw)


def _areas(verts, tris):
    v = verts.astype(float)
    return 0.5 * np.linalg.norm(np.cross(v[tris[:, 1]] - v[tris[:, 0]], v[tris[:, 2]] - v[tris[:, 0]]), axis=1)


def test_polygons_have_the_cross_section_area():
    """Unit cube cut perpendicular to its diagonal: the middle plane is the regular hexagon of area
    3 sqrt(3) / 4; an axis-aligned cut is the unit square; planes outside give nothing."""
    corners = box_corners(np.zeros(3), np.ones(3), np.eye(4))
    f = np.ones(3) / np.sqrt(3)
    r = np.cross(f, [0, 0, 1.0])
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    eye = -2 * f
    mid_depth = 2 + np.sqrt(3) / 2
    verts, tris, first = slice_polygons(corners, eye, (r, u, f), np.array([mid_depth, 100.0, mid_depth - 0.3]))
    a = _areas(verts, tris)
    assert a[first[0]:first[1]].sum() == pytest.approx(3 * np.sqrt(3) / 4, rel=1e-5)
    assert first[2] - first[1] == 0                                # the far plane misses the cube
    assert first[1] - first[0] == 4                                # a hexagon is a fan of 4 triangles
    f2 = np.array([0, 0, 1.0])
    verts, tris, first = slice_polygons(corners, [0.5, 0.5, -3.0], ((1.0, 0, 0), (0, 1.0, 0), f2),
                                        np.array([3.4]))
    assert _areas(verts, tris).sum() == pytest.approx(1.0, rel=1e-6)
