"""Lights and lighting settings as data: kinds, camera-attached lights, JSON round trip, many lights."""

from __future__ import annotations

import json

import numpy as np
import pytest

from tests.render.render_helpers import sphere_volume
from volumen.core import Camera, Environment, Light, Sampling, Scene, Shading, TransferFunction
from volumen.render import render

TF = TransferFunction(color=((-1000, 1, 1, 1), (1000, 0.9, 0.6, 0.4)), opacity=((-1000, 0), (0, 0.05), (1000, 0.6)))


@pytest.fixture(scope="module")
def vol():
    return sphere_volume(n=32, radius=10.0, smooth=2.0)


def test_light_and_shading_round_trip_and_old_files():
    lights = (Light(position=(1, 2, 3), direction=(0, 1, 0), exponent=3, kind="spot", radius=2.5),
              Light(kind="headlight", exponent=8, color=(1, 0.9, 0.8)),
              Light(position=(10, 0, 0), direction=(-1, 0, 1), attach="camera", intensity=0.4))
    sh = Shading(mode="pathtrace", shadow_method="direct", shadow_offset=1.5, shadow_step=0.5, light_volume_scale=1.0,
                 sigma_a=0.3, sigma_s=0.7, phase_g=-0.2, pt_samples=16, pt_bounces=8)
    s = Scene(lights=lights, shading=sh)
    back = Scene.from_json(s.to_json())
    assert back == s and back.lights == lights and back.shading == sh
    # files written before lights had a kind: exponent > 0 means a spot, else a point light
    old = {"lights": [{"position": [0, 0, 1], "direction": [0, 0, -1], "intensity": 1.0, "color": [1, 1, 1],
                       "exponent": 4.0}, {"position": [0, 0, 1]}], "shading": {"mode": "phong"}}
    s2 = Scene.from_dict(json.loads(json.dumps(old)))
    assert [lt.kind for lt in s2.lights] == ["spot", "point"]
    assert s2.shading.shadow_method == "fast" and s2.shading.light_volume_scale == 2.0


def test_shading_grouped_per_model_and_flat_files_still_load():
    from volumen.core._lighting import PathTraceSettings, PhongSettings, ScatterSettings, ShadowSettings

    sh = Shading(mode="scattering", phong=PhongSettings(ambient=0.3, gradient="sobel"),
                 shadows=ShadowSettings(method="direct", step=0.5), scattering=ScatterSettings(phase_g=0.4),
                 pathtrace=PathTraceSettings(samples=8))
    d = json.loads(sh.to_json())
    assert set(d) == {"mode", "phong", "shadows", "scattering", "pathtrace"} and d["shadows"]["method"] == "direct"
    assert Shading.from_json(sh.to_json()) == sh and Shading.from_dict(d) == sh  # nested dicts load too
    flat = {"mode": "scattering", "ambient": 0.3, "gradient": "sobel", "shadow_method": "direct", "shadow_step": 0.5,
            "phase_g": 0.4, "pt_samples": 8}  # a settings file written before the grouping
    assert Shading.from_dict(json.loads(json.dumps(flat))) == sh
    assert Shading(**flat) == sh and sh.ambient == 0.3 and sh.pt_samples == 8  # flat names stand for the fields
    with pytest.raises(ValueError, match="unknown Shading fields"):
        Shading.from_dict({"mode": "phong", "ambiant": 0.2})


@pytest.mark.parametrize("make,match", [
    (lambda: Light(kind="area"), "headlight"),
    (lambda: Light(attach="patient"), "camera"),
    (lambda: Light(radius=-1), "radius"),
    (lambda: Shading(shadow_method="slow"), "direct"),
    (lambda: Shading(phase_g=0.99), "phase_g"),
    (lambda: Shading(sigma_a=0, sigma_s=0), "sigma"),
    (lambda: Shading(pt_samples=0), "pt_samples"),
    (lambda: Shading(light_volume_scale=8), "light_volume_scale"),
])
def test_bad_lighting_settings_raise(make, match):
    with pytest.raises(ValueError, match=match):
        make()


@pytest.mark.parametrize("shading", ["phong", "shadows", "scattering"])
def test_camera_attached_light_equals_the_world_light_it_stands_for(vol, shading):
    cam = Camera.orbit(vol, azimuth=35, elevation=20, zoom=1.3)
    r, u, f = cam.basis()
    offset, direction = np.array([20.0, 15.0, 5.0]), np.array([-0.2, -0.1, 1.0])
    attached = Light(position=tuple(offset), direction=tuple(direction), exponent=3.0, attach="camera")
    world = Light(position=tuple(np.asarray(cam.position) + offset[0] * r + offset[1] * u + offset[2] * f),
                  direction=tuple(direction[0] * r + direction[1] * u + direction[2] * f), exponent=3.0)
    base = Scene(volume=vol, transfer=TF, shading=Shading(mode=shading))
    a = render(base.with_(lights=(attached,)), cam, (32, 32))
    b = render(base.with_(lights=(world,)), cam, (32, 32))
    assert a.rgba[..., :3].max() > 0.1
    np.testing.assert_allclose(a.rgba, b.rgba, atol=1e-5)


def test_headlight_kind_is_the_headlight_shading(vol):
    cam = Camera.orbit(vol, azimuth=-40, zoom=1.3)
    base = Scene(volume=vol, transfer=TF)
    head = render(base.with_(shading=Shading(mode="headlight")), cam, (32, 32))
    kind = render(base.with_(shading=Shading(mode="phong"), lights=(Light(kind="headlight"),)), cam, (32, 32))
    np.testing.assert_allclose(head.rgba, kind.rgba, atol=1e-6)


def test_sixteen_lights_in_one_scene(vol):
    """16 coloured lights round the ball (shadows, fast): the picture is the sum of the single-light ones."""
    cam = Camera.orbit(vol, zoom=1.3)
    c = np.asarray(vol.center)
    rng = np.random.default_rng(3)
    dirs = rng.normal(size=(16, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    lights = tuple(Light(position=tuple(c + 90 * d), intensity=0.06, color=tuple(rng.uniform(0.3, 1, 3)))
                   for d in dirs)
    # uniform: the ambient-only term (with no lights of its own, "auto" would light the scene with the studio rig)
    base = Scene(volume=vol, transfer=TF, sampling=Sampling(seed=2), environment=Environment(kind="uniform"))
    all_ = render(base.with_(lights=lights, shading=Shading(mode="shadows")), cam, (24, 24))
    assert all_.stats["light_volumes_built"] == 16
    total = render(base.with_(shading=Shading(mode="shadows")), cam, (24, 24)).rgba
    for lt in lights:
        total[..., :3] += render(base.with_(lights=(lt,), shading=Shading(mode="shadows", ambient=0.0)), cam,
                                 (24, 24)).rgba[..., :3]
    assert all_.rgba[..., :3].max() < 0.99
    np.testing.assert_allclose(all_.rgba, total, atol=5e-5)
