"""Lighting identities: headlight = a point light at the eye; lights add up."""

from __future__ import annotations

import numpy as np
import pytest
from render_helpers import sphere_volume, three_lights

from volumen.core import Camera, Environment, Isosurface, Light, Sampling, Scene, Shading, TransferFunction
from volumen.render import render

TF = TransferFunction(color=((-1000, 1, 1, 1), (1000, 0.9, 0.6, 0.4)), opacity=((-1000, 0), (0, 0.05), (1000, 0.6)))


@pytest.fixture(scope="module")
def vol():
    return sphere_volume(n=40, radius=12.0, smooth=2.0)


@pytest.mark.parametrize("mode", ["composite", "isosurface"])
def test_headlight_equals_point_light_at_eye(vol, mode):
    cam = Camera.orbit(vol, azimuth=30, elevation=20, zoom=1.4)
    _, _, f = cam.basis()
    base = Scene(volume=vol, mode=mode, transfer=TF, isosurface=Isosurface(value=0.0))
    head = render(base.with_(shading=Shading(mode="headlight")), cam, (48, 48))
    spot = Light(position=cam.position, direction=tuple(f), exponent=0.0)
    lit = render(base.with_(shading=Shading(mode="phong"), lights=(spot,)), cam, (48, 48))
    assert head.rgba[..., 3].max() > 0.5
    assert np.abs(head.rgba - lit.rgba).max() < 1e-5


def test_lights_add_up(vol):
    cam = Camera.orbit(vol, azimuth=-25, zoom=1.4)
    c = np.asarray(vol.center)
    lights = three_lights(c)
    sh = Shading(mode="phong", ambient=0.15)
    # uniform: the ambient-only term (with no lights of its own, "auto" would light the scene with the studio rig)
    base = Scene(volume=vol, transfer=TF, sampling=Sampling(seed=7), environment=Environment(kind="uniform"))

    def go(lts, shading):
        return render(base.with_(lights=lts, shading=shading), cam, (48, 48)).rgba

    all_lights = go(lights, sh)
    ambient = go((), sh)
    parts = [go((lt,), Shading(mode="phong", ambient=0.0)) for lt in lights]
    total = ambient.copy()
    for p in parts:
        total[..., :3] += p[..., :3]
    assert all_lights[..., :3].max() < 0.99  # no clamping involved
    assert min(p[..., :3].max() for p in parts) > 0.02  # every light contributes
    np.testing.assert_allclose(all_lights, total, atol=2e-5)
