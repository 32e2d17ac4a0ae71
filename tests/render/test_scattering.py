"""Single scattering against its closed form; the Henyey-Greenstein phase; lights add linearly.

The model (``volumen.render.raycast._scatter``): extinction
``sigma_t = (sigma_a + sigma_s) mu`` with ``mu = -ln(1 - alpha) / ds0`` the
transfer function's extinction, albedo ``sigma_s / (sigma_a + sigma_s)``, and
radiance toward the eye ``L = integral T_eye(t) sigma_s c S(t) dt`` with
``S = ambient + diffuse * sum_l 4 pi p_HG(cos) E_l T_l``.
"""

from __future__ import annotations

import numpy as np
import pytest

from tests.render.render_helpers import axis_camera, sphere_volume, three_lights
from volumen.core import Camera, Environment, Light, Sampling, Scene, Shading, TransferFunction, Volume
from volumen.render import render
from volumen.render.optics import hg_phase

A0 = 0.04
COLOR = np.array([1.0, 0.6, 0.3])


def _slab_closed_form(L, mu, sigma_a, sigma_s, g, ka, kd, E, offset):
    """Slab of thickness L (mm) seen along its normal; a far light behind the eye on the same axis.

    At depth t the eye sees through ``exp(-st t)`` (st = (sigma_a + sigma_s) mu); the light enters through
    the same face, and the path to it starts ``offset`` mm off the sample, so ``T_l = exp(-st max(t - o, 0))``;
    light and view directions are opposite (cos theta = -1). Then

        L_out / (albedo c) = ka (1 - e^{-st L}) + kd 4 pi p(-1) E [ (1 - e^{-st o})
                              + e^{st o} (e^{-2 st o} - e^{-2 st L}) / 2 ]      (for o < L)
    """
    st = (sigma_a + sigma_s) * mu
    albedo = sigma_s / (sigma_a + sigma_s)
    p = 4 * np.pi * (1 - g * g) / (4 * np.pi * (1 + g) ** 3)
    o = offset
    light = (1 - np.exp(-st * o)) + np.exp(st * o) * (np.exp(-2 * st * o) - np.exp(-2 * st * L)) / 2
    return albedo * COLOR * (ka * (1 - np.exp(-st * L)) + kd * p * E * light), 1 - np.exp(-st * L)


@pytest.mark.parametrize("method", ["fast", "direct"])
@pytest.mark.parametrize("g", [0.0, -0.4, 0.5])
def test_homogeneous_slab_matches_closed_form(method, g):
    nz = 40
    vol = Volume(np.full((nz, 12, 12), 100, np.int16), spacing=(1.0, 1.0, 1.0))  # int16: the phantoms' kernel
    cam, size = axis_camera(vol, "superior")
    tf = TransferFunction(color=((0, *COLOR), (200, *COLOR)), opacity=((0, A0), (200, A0)))
    light = Light(position=(5.5, 5.5, 1e4), intensity=0.3)  # far above the eye, on the view axis
    sh = Shading(mode="scattering", shadow_method=method, sigma_a=0.5, sigma_s=1.0, phase_g=g,
                 ambient=0.1, diffuse=0.9, shadow_offset=2.0)
    im = render(Scene(volume=vol, transfer=tf, lights=(light,), shading=sh, sampling=Sampling(jitter=False)),
                cam, size)
    mu = -np.log(1 - A0) / 1.0
    rgb, alpha = _slab_closed_form(nz - 1.0, mu, 0.5, 1.0, g, 0.1, 0.9, 0.3, 2.0)
    assert rgb.max() < 0.95  # no clamping
    got = im.rgba[2:-2, 2:-2].reshape(-1, 4)
    np.testing.assert_allclose(got[:, 3], alpha, rtol=0.005)
    np.testing.assert_allclose(got[:, :3], np.broadcast_to(rgb, got[:, :3].shape), rtol=0.02)


@pytest.mark.parametrize("g", [-0.9, -0.5, 0.0, 0.3, 0.7, 0.9])
def test_henyey_greenstein_integrates_to_one(g):
    # integral over the sphere = 2 pi integral_{-1}^{1} p(mu) dmu, Gauss-Legendre on the njit function itself
    x, w = np.polynomial.legendre.leggauss(400)
    total = 2 * np.pi * sum(wi * hg_phase(xi, g) for xi, wi in zip(x, w, strict=True))
    assert abs(total - 1.0) < 1e-6, total
    # its mean cosine is g
    mean_cos = 2 * np.pi * sum(wi * xi * hg_phase(xi, g) for xi, wi in zip(x, w, strict=True))
    assert abs(mean_cos - g) < 1e-6


@pytest.mark.parametrize("mode", ["scattering", "shadows"])
def test_lights_add_linearly(mode):
    vol = sphere_volume(n=40, radius=12.0, smooth=2.0)
    tf = TransferFunction(color=((-1000, 1, 1, 1), (1000, 0.9, 0.6, 0.4)),
                          opacity=((-1000, 0), (0, 0.05), (1000, 0.6)))
    cam = Camera.orbit(vol, azimuth=-25, zoom=1.4)
    c = np.asarray(vol.center)
    lights = three_lights(c)
    # uniform: the ambient-only term (with no lights of its own, "auto" would light the scene with the studio rig)
    base = Scene(volume=vol, transfer=tf, sampling=Sampling(seed=7), environment=Environment(kind="uniform"))

    def go(lts, ambient):
        sh = Shading(mode=mode, ambient=ambient, phase_g=0.3, sigma_a=0.2, sigma_s=0.9)
        return render(base.with_(lights=lts, shading=sh), cam, (40, 40)).rgba

    all_lights = go(lights, 0.15)
    total = go((), 0.15)  # the ambient term, once
    parts = [go((lt,), 0.0) for lt in lights]
    for p in parts:
        total[..., :3] += p[..., :3]
    assert all_lights[..., :3].max() < 0.99  # no clamping involved
    assert min(p[..., :3].max() for p in parts) > 0.02  # every light contributes
    np.testing.assert_allclose(all_lights, total, atol=2e-5)


def test_scattering_fast_matches_direct_light_paths():
    """The scattering model reads the same illumination volumes (built with its extinction) as shadows."""
    vol = sphere_volume(n=48, radius=14.0, smooth=1.5)
    tf = TransferFunction(color=((-1000, 1, 1, 1), (1000, 1, 0.7, 0.5)), opacity=((-1000, 0), (0, 0.02), (1000, 0.3)))
    cam = Camera.orbit(vol, azimuth=20, elevation=15, zoom=1.3)
    c = np.asarray(vol.center)
    lights = (Light(position=tuple(c + [90, 40, 60])), Light(position=tuple(c + [-60, 80, -30]), color=(0.6, 0.8, 1)))
    scene = Scene(volume=vol, transfer=tf, lights=lights)
    ims = [render(scene.with_(shading=Shading(mode="scattering", shadow_method=m, sigma_a=0.3, sigma_s=1.2,
                                              phase_g=0.4)), cam, (48, 48)) for m in ("fast", "direct")]
    d = np.abs(ims[0].rgba - ims[1].rgba).reshape(-1, 4)
    assert ims[1].rgba[..., :3].max() > 0.2
    assert d.mean(axis=0).max() <= 0.01 and np.percentile(d, 99, axis=0).max() <= 0.05
