"""The isosurface of a sphere: hit points lie on the analytic sphere within a quarter voxel."""

from __future__ import annotations

import numpy as np
import pytest

from volumen.core import Camera, Isosurface, Sampling, Scene, Shading, Volume
from volumen.render import render

R = 13.3
CENTRE = np.array([23.4, 22.7, 24.1])  # world mm (x, y, z)
SPACING = (1.0, 0.9, 1.1)  # dz, dy, dx


@pytest.fixture(scope="module")
def sdf():
    nz, ny, nx = 46, 52, 44
    k, j, i = np.mgrid[:nz, :ny, :nx].astype(np.float64)
    x, y, z = i * SPACING[2], j * SPACING[1], k * SPACING[0]
    d = R - np.sqrt((x - CENTRE[0]) ** 2 + (y - CENTRE[1]) ** 2 + (z - CENTRE[2]) ** 2)
    return Volume(d.astype(np.float32), spacing=SPACING)


def _rays(cam, size):
    """Independent ray directions (world) for every pixel centre, (H, W, 3) origins and directions."""
    w, h = size
    r, u, f = cam.basis()
    cx = (np.arange(w) + 0.5 - w / 2) / (h / 2)
    cy = (h / 2 - np.arange(h) - 0.5) / (h / 2)
    sx, sy = np.meshgrid(cx, cy)
    if cam.projection == "orthographic":
        o = np.asarray(cam.position) + (sx[..., None] * r + sy[..., None] * u) * cam.parallel_scale
        d = np.broadcast_to(f, o.shape)
    else:
        t = np.tan(np.radians(cam.fov) / 2)
        d = f + (sx[..., None] * r + sy[..., None] * u) * t
        d = d / np.linalg.norm(d, axis=-1, keepdims=True)
        o = np.broadcast_to(np.asarray(cam.position), d.shape)
    return o, d


@pytest.mark.parametrize("projection", ["orthographic", "perspective"])
@pytest.mark.parametrize("view", ["superior", "left"])
def test_sphere_radius_from_depth(sdf, projection, view):
    cam = Camera.orbit(sdf, view=view, projection=projection, zoom=1.6)
    size = (56, 56)
    scene = Scene(volume=sdf, mode="isosurface", isosurface=Isosurface(value=0.0), shading=Shading(mode="headlight"),
                  sampling=Sampling(samples_per_voxel=1.0))
    im = render(scene, cam, size)
    o, d = _rays(cam, size)
    # analytic: nearest intersection of each ray with the sphere
    oc = o - CENTRE
    b = np.einsum("...i,...i", oc, d)
    disc = b * b - (np.einsum("...i,...i", oc, oc) - R * R)
    hit_true = disc > 0
    t_true = -b - np.sqrt(np.where(hit_true, disc, 0))
    # away from grazing rays (the last 20 % of the radius), where depth is ill-conditioned
    inner = disc > (0.6 * R) ** 2
    assert inner.sum() > 200
    assert np.all(np.isfinite(im.depth[inner]))
    assert np.all(im.rgba[..., 3][inner] == 1.0)
    quarter_voxel = 0.25 * min(SPACING)
    np.testing.assert_allclose(im.depth[inner], t_true[inner], atol=quarter_voxel)
    # and the radius of the hit points
    p = o[inner] + d[inner] * im.depth[inner][:, None]
    radius = np.linalg.norm(p - CENTRE, axis=-1)
    assert np.abs(radius - R).max() < quarter_voxel
    # no hits where the ray misses the sphere by more than a voxel
    far_miss = (~hit_true) & (np.sqrt(np.maximum(np.einsum("...i,...i", oc, oc) - b * b, 0)) > R + 1.5)
    assert np.all(np.isinf(im.depth[far_miss])) and np.all(im.rgba[..., 3][far_miss] == 0)
