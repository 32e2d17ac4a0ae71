"""The environment light: its spherical harmonics against brute-force integrals, its importance
sampling against its own density, the studio rig, maps read from HDR files, and the majorant grid and Sobol
sampler the path tracer tracks and draws with."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.stats import qmc

from volumen.core import Camera, Environment, Scene, Shading, Volume, studio_lights, studio_sky
from volumen.render.raycast import pack_frame
from volumen.render.raycast._environment import env_pdf, env_sample, sh_irradiance, sh_phase
from volumen.render.raycast._majorant import majorant_grid
from volumen.render.raycast._precompute import build_blocks
from volumen.render.raycast._sobol import draw, path_key, sobol_point


def _env(kind="studio", **kw):
    """``(camera, frame arrays)``: the kernels' own record (``raycast.Arrays``) of a tiny lit scene in the
    environment (a record of the tests' own would enter Numba's cache index, which other processes then cannot
    read)."""
    cam = Camera(position=(0.0, -100.0, 0.0), target=(0.0, 0.0, 0.0), up=(0.0, 0.0, 1.0))
    vol = Volume(np.zeros((4, 4, 4), np.float32), spacing=(1.0, 1.0, 1.0))
    scene = Scene(volume=vol, shading=Shading(mode="phong"), environment=Environment(kind=kind, **kw))
    return cam, pack_frame(scene, cam, (4, 4)).arrays


def _sphere(n=200_000, seed=1):
    v = np.random.default_rng(seed).normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def test_sky_irradiance_from_its_harmonics_matches_the_integral():
    """E(n) / pi of the studio sky from its order-2 SH against a Monte Carlo integral of L(w) max(n.w, 0) / pi
    over 200,000 directions: within 2 % (the sky is smooth: order 2 holds nearly all of its irradiance)."""
    cam, a = _env()
    up = np.asarray(cam.basis()[1])
    w = _sphere()
    rad = studio_sky(w @ up)
    for n in (up, -up, np.asarray(cam.basis()[0]), (up + np.array([0.6, 0.0, 0.0])) / np.linalg.norm(
            up + np.array([0.6, 0.0, 0.0]))):
        want = (rad * np.maximum(w @ n, 0.0)[:, None]).mean(axis=0) * 4.0  # (4 pi / N) sum / pi
        got = np.array(sh_irradiance(a, *n))
        np.testing.assert_allclose(got, want, rtol=0.02)
    # the phase-weighted radiance of an isotropic medium is the mean radiance
    np.testing.assert_allclose(sh_phase(a, *up, 0.0), rad.mean(axis=0), rtol=0.01)


def test_environment_sampling_draws_its_own_density():
    """Directions drawn from the map's tables have the density env_pdf gives them: E[1 / pdf] = 4 pi, and
    E[f / pdf] is the integral of f (here the radiance, against a direct sum over the pixels)."""
    img = np.random.default_rng(3).lognormal(0.0, 1.0, (16, 32, 3)).astype(np.float32)
    _, a = _env("map", image=img)
    rng = np.random.default_rng(4)
    inv, lum = [], []
    for u1, u2 in rng.random((40_000, 2)):
        dx, dy, dz, pdf = env_sample(a, u1, u2)
        assert env_pdf(a, dx, dy, dz) == pytest.approx(pdf, rel=1e-6)
        inv.append(1.0 / pdf)
        i = min(int(math.acos(max(min(dz, 1.0), -1.0)) * 16 / math.pi), 15)
        j = min(int((math.atan2(dy, dx) % (2 * math.pi)) * 32 / (2 * math.pi)), 31)
        lum.append(img[i, j, 1] / pdf)
    assert np.mean(inv) == pytest.approx(4 * math.pi, rel=0.02)
    th = (np.arange(16) + 0.5) * math.pi / 16
    solid = np.sin(th)[:, None] * (math.pi / 16) * (2 * math.pi / 32)
    assert np.mean(lum) == pytest.approx(float((img[..., 1] * solid).sum()), rel=0.03)


def test_studio_lights_key_fill_rim_around_the_camera():
    cam = Camera(position=(0.0, -300.0, 0.0), target=(0.0, 0.0, 0.0), up=(0.0, 0.0, 1.0))
    key, fill, rim = studio_lights(cam, (0.0, 0.0, 0.0), 100.0)
    r, u, f = cam.basis()
    k = np.asarray(key.position)
    assert k @ u > 0 and k @ r < 0 and k @ f < 0  # upper left front
    assert np.dot(fill.position, r) > 0 and np.dot(rim.position, f) > 0  # fill from the right, rim from behind
    assert key.intensity > rim.intensity > fill.intensity and key.radius > 0
    assert np.linalg.norm(key.position) == pytest.approx(200.0)


def test_environment_round_trips_json_without_its_pixels():
    env = Environment(kind="map", map="/data/sky.hdr", intensity=2.0, rotation=30.0,
                      image=np.ones((4, 8, 3), np.float32))
    back = Environment.from_dict(env.to_dict())
    assert back == env and back.image is None and "image" not in env.to_dict()
    s = Scene(environment=Environment(kind="studio"))
    assert Scene.from_json(s.to_json()) == s
    with pytest.raises(ValueError, match="map"):
        Environment(kind="map")
    assert Environment().resolved(False).kind == "studio" and Environment().resolved(True).kind == "uniform"


def test_environment_map_read_from_an_hdr_file(tmp_path):
    iio = pytest.importorskip("imageio.v2")
    img = np.random.default_rng(0).lognormal(0.0, 1.0, (8, 16, 3)).astype(np.float32)
    try:
        iio.imwrite(tmp_path / "sky.hdr", img, format="HDR-FI")
    except RuntimeError as exc:
        pytest.skip(f"FreeImage (Debian libfreeimage3, make system-libs) is missing: {exc}")
    from volumen.io import read_environment

    back = read_environment(tmp_path / "sky.hdr")
    err = np.abs(back - img).max(axis=-1) / img.max(axis=-1)
    assert err.max() < 1 / 64  # RGBE: 8-bit mantissas sharing the largest channel's exponent


def test_majorants_bound_every_sample_in_their_block():
    """The majorant of a block is at least the extinction of any trilinear sample inside it (random points)."""
    rng = np.random.default_rng(5)
    u = (rng.random((21, 19, 23)) ** 3 * 4095).astype(np.float32)
    u[:, :, :10] *= 0.05  # a darker part: its blocks have lower majorants
    sig = np.cumsum(rng.random(4096)) % 7.0  # not monotonic
    bmin, bmax = build_blocks(u, 8)
    maj = majorant_grid(sig, bmin, bmax, 2.0)
    from scipy.ndimage import map_coordinates

    p = rng.random((3, 20000)) * (np.array(u.shape)[:, None] - 1)
    v = map_coordinates(u, p, order=1)
    s = 2.0 * sig[np.clip(np.rint(v).astype(int), 0, 4095)]
    cell = tuple((p // 8).astype(int))
    assert np.all(s <= maj[cell] * (1 + 1e-6))
    assert maj.min() < maj.max()  # per block, not one global bound


def test_sobol_points_and_their_stratification():
    """The unscrambled points are scipy's Sobol points (the same set of 256 in 4 dimensions); scrambled per
    pixel, the first 16 samples of a pixel fall one per cell of the 4 x 4 grid of any two dimensions of a pad."""
    ref = {tuple(r) for r in qmc.Sobol(4, scramble=False).random_base2(8)}
    mine = {tuple(sobol_point(i, d) / 2**32 for d in range(4)) for i in range(256)}
    assert mine == ref
    for pixel in (0, 77):
        pts = np.array([[draw(np.uint64(path_key(3, pixel, s)), d) for d in range(8)] for s in range(16)])
        for a, b in ((0, 1), (2, 3), (4, 6)):
            assert len({(int(x * 4), int(y * 4)) for x, y in pts[:, [a, b]]}) == 16
    x = np.array([draw(np.uint64(path_key(1, p, 5)), 9) for p in range(20000)])
    assert abs(x.mean() - 0.5) < 0.01 and abs(12 * x.var() - 1) < 0.03
