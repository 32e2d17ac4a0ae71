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
    # int16 in micrometres (0.5 um rounding), so the pictures run the int16 kernels CT compiles anyway
    return Volume(np.rint(d * 1000).astype(np.int16), spacing=SPACING)


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


# --- the eye's side: an eye inside a bright lumen sees its wall ---
RT = 9.2  # tube radius, mm
AXIS = np.array([30.3, 29.6])  # tube axis (x, y), world mm, along z


@pytest.fixture(scope="module")
def tube():
    """A contrast-filled tube along z: 2000 inside radius RT, 200 outside (a wall darker than the lumen), edge
    smoothed linearly over 2 mm so the 1100 level lies exactly at RT."""
    nz, ny, nx = 40, 60, 60
    k, j, i = np.mgrid[:nz, :ny, :nx].astype(np.float64)
    rho = np.hypot(i - AXIS[0], j - AXIS[1])
    data = 1100.0 + 900.0 * np.clip((RT - rho) / 1.0, -1.0, 1.0)
    return Volume(np.rint(data).astype(np.int16), spacing=(1.0, 1.0, 1.0))  # rounded HU: <= 0.6 um off


def _iso_scene(vol):
    return Scene(volume=vol, mode="isosurface", isosurface=Isosurface(value=1100.0), shading=Shading(mode="headlight"),
                 sampling=Sampling(samples_per_voxel=2.0, jitter=False))


@pytest.mark.parametrize("direction", [(1.0, 0.0, 0.0), (0.6, -0.5, 0.62)])
def test_eye_inside_bright_tube_sees_the_wall(tube, direction):
    eye = np.array([AXIS[0] + 1.7, AXIS[1] - 2.1, 19.5])
    d = np.asarray(direction) / np.linalg.norm(direction)
    cam = Camera(position=tuple(eye), target=tuple(eye + 10 * d), up=(0, 0, 1) if abs(d[2]) < 0.9 else (0, 1, 0),
                 fov=50.0)
    size = (24, 20)
    im = render(_iso_scene(tube), cam, size)
    o, dirs = _rays(cam, size)
    # analytic distance from the eye to the cylinder rho = RT along each ray (eye inside: the positive root)
    px, py = eye[0] - AXIS[0], eye[1] - AXIS[1]
    a = dirs[..., 0] ** 2 + dirs[..., 1] ** 2
    b = px * dirs[..., 0] + py * dirs[..., 1]
    c = px * px + py * py - RT * RT
    with np.errstate(invalid="ignore", divide="ignore"):
        t = (-b + np.sqrt(b * b - a * c)) / a
    z = eye[2] + t * dirs[..., 2]
    ok = (z > 1.0) & (z < 38.0)  # hits on the wall, not through the volume's ends
    assert ok.sum() > 0.8 * ok.size
    err = np.abs(im.depth[ok] - t[ok])
    print(f"eye in a bright tube, direction {direction}: depth error mean {err.mean():.3f} mm, max {err.max():.3f} mm")
    assert np.isfinite(im.depth[ok]).all() and err.max() <= 0.25
    assert im.depth[ok].min() > 1.0  # not the near plane


def test_eye_outside_the_tube_sees_its_outer_wall(tube):
    """Eye inside the volume but in the dark region: the rising crossing, as before."""
    eye = np.array([AXIS[0] + 22.0, AXIS[1], 20.0])
    cam = Camera(position=tuple(eye), target=(AXIS[0], AXIS[1], 20.0), up=(0, 0, 1), fov=20.0)
    im = render(_iso_scene(tube), cam, (9, 9))
    assert abs(im.depth[4, 4] - (22.0 - RT)) <= 0.25, im.depth[4, 4]
