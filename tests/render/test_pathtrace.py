"""Progressive path tracing: converges to the single-scattering picture, noise falls like 1/sqrt(N),
deterministic, and energy-conserving (white furnace).

The two convergence tests run on the head phantom and on the same scene with a label map (bone and a ball
inside the head drawn in their own colours and opacities, the rest with the scan's transfer function): the
path tracer's tracking and colours classify through the labels as the ray caster's primary rays and
illumination volumes do, and converge to its picture with the same tolerances.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from render_helpers import sphere_volume

from volumen.core import Camera, Environment, LabelLayer, LabelMap, Light, Sampling, Scene, Shading, TransferFunction
from volumen.data import phantom
from volumen.render import PathTracer, render

SIZE = (32, 32)


@pytest.fixture(scope="module")
def head_scene():
    vol = phantom("head", size=48)
    cam = Camera.orbit(vol, azimuth=-30, elevation=10, zoom=1.2)
    r, u, f = cam.basis()
    c = np.asarray(vol.center)
    pos = c + vol.diagonal * (0.7 * r + 0.7 * u - 0.6 * f)
    lights = (Light(position=tuple(pos), direction=tuple(c - pos), exponent=2.0, intensity=0.9),
              Light(position=tuple(c - vol.diagonal * (0.8 * r + 0.2 * f)), color=(0.5, 0.7, 1.0), intensity=0.5))
    tf = TransferFunction.preset("ct-skin-bone")
    sh = Shading(mode="scattering", sigma_a=0.2, sigma_s=1.0, phase_g=0.3, pt_bounces=1, ambient=0.2, diffuse=0.8,
                 pt_denoise=False)
    return Scene(volume=vol, transfer=tf, lights=lights, shading=sh, sampling=Sampling(jitter=False)), cam


def _with_labels(scene):
    """The scene with a label map: bone (above 400 HU) and a ball in the head, solid, over the scan's preset."""
    vol = scene.volume
    z, y, x = np.indices(vol.shape)
    c = (np.asarray(vol.shape) - 1) / 2
    lab = np.zeros(vol.shape, np.uint8)
    lab[(z - c[0]) ** 2 + (y - c[1]) ** 2 + (x - c[2] - 4) ** 2 <= 8.5 ** 2] = 2
    lab[vol.data > 400] = 1
    labels = LabelMap(lab, vol.spacing, vol.affine, {1: "bone", 2: "ball"}, {1: (0.95, 0.9, 0.8), 2: (0.9, 0.2, 0.2)})
    return scene.with_(labels=LabelLayer(labels, opacity={"bone": 0.6, "ball": 0.35}))


@pytest.fixture(scope="module", params=["scan", "labels"])
def lit_scene(request, head_scene):
    scene, cam = head_scene
    return (_with_labels(scene) if request.param == "labels" else scene), cam


def test_single_scattering_converges_to_the_scattering_model(lit_scene, output_dir):
    scene, cam = lit_scene
    tag = "" if scene.labels is None else "_labels"
    ref = render(scene, cam, SIZE)
    pt = PathTracer(scene, cam, SIZE)
    im = pt.step(256)
    im = pt.step(256)
    assert im.stats["spp"] == 512
    out = output_dir / "lighting"
    out.mkdir(exist_ok=True)
    ref.save(out / f"pt_head{tag}_scattering.png")
    im.save(out / f"pt_head{tag}_pathtrace_512spp.png")
    d = np.abs(im.rgba - ref.rgba)
    assert ref.rgba[..., :3].mean() > 0.05
    assert d.mean() < 0.02, d.mean(axis=(0, 1))
    # no bias: the mean over the picture agrees far better than any pixel
    assert np.abs(im.rgba.mean(axis=(0, 1)) - ref.rgba.mean(axis=(0, 1))).max() < 0.005


def test_noise_falls_like_one_over_sqrt_samples(lit_scene):
    scene, cam = lit_scene
    reference = PathTracer(scene.with_(sampling=Sampling(jitter=False, seed=99)), cam, SIZE).step(1024).rgba
    pt = PathTracer(scene, cam, SIZE)
    rms_n = np.sqrt(np.mean((pt.step(16).rgba - reference)[..., :3] ** 2))
    rms_4n = np.sqrt(np.mean((pt.step(48).rgba - reference)[..., :3] ** 2))  # 64 samples in all
    assert 1.6 <= rms_n / rms_4n <= 2.5, (rms_n, rms_4n)


def test_progressive_steps_are_deterministic(head_scene):
    scene, cam = head_scene
    a = PathTracer(scene, cam, (16, 16))
    a.step(3)
    a = a.step(5).rgba
    b = PathTracer(scene, cam, (16, 16)).step(8).rgba
    np.testing.assert_array_equal(a, b)
    c = PathTracer(scene.with_(sampling=Sampling(jitter=False, seed=5)), cam, (16, 16)).step(8).rgba
    assert np.abs(a - c).max() > 0  # another seed, other samples
    via_render = render(scene.with_(shading=Shading(mode="pathtrace", pt_samples=8, sigma_a=0.2, sigma_s=1.0,
                                                    phase_g=0.3, pt_bounces=1, ambient=0.2, diffuse=0.8,
                                                    pt_denoise=False)),
                        cam, (16, 16))
    np.testing.assert_array_equal(via_render.rgba, b)
    assert via_render.stats["spp"] == 8


def _furnace(environment):
    vol = sphere_volume(n=32, radius=11.0, smooth=2.0)
    tf = TransferFunction(color=((-1000, 1, 1, 1), (1000, 1, 1, 1)), opacity=((-1000, 0), (0, 0.2), (1000, 0.5)))
    sh = Shading(mode="pathtrace", sigma_a=0.0, sigma_s=1.0, phase_g=0.5, ambient=1.0, pt_bounces=100000,
                 pt_samples=32, pt_denoise=False)
    return Scene(volume=vol, transfer=tf, shading=sh, environment=environment), Camera.orbit(vol, zoom=1.3)


def test_white_furnace_multiple_scattering_conserves_energy():
    """A white, non-absorbing medium in a uniform environment of radiance 1 looks uniformly of radiance 1:
    every path that enters leaves with throughput 1, so the colour is the fraction of paths that met the medium,
    exactly, however many bounces; that fraction converges to the opacity along the view ray (alpha)."""
    scene, cam = _furnace(Environment(kind="uniform"))
    pt = PathTracer(scene, cam, (24, 24))
    im = pt.step(32)
    a = im.rgba[..., 3]
    assert a.max() > 0.9
    hits = pt.acc[..., 3] / pt.spp
    np.testing.assert_allclose(im.rgba[..., :3], np.repeat(hits[..., None], 3, axis=-1), atol=1e-6)
    assert np.abs(hits - a).mean() < 0.03 and abs(hits.mean() - a.mean()) < 0.005
    # with absorption, multiple scattering loses energy; single scattering sees the environment unshadowed
    absorbing = render(scene.with_(shading=replace(scene.shading, sigma_a=0.5)), cam, (24, 24))
    assert absorbing.rgba[..., 0].sum() < 0.9 * absorbing.rgba[..., 3].sum()


def test_white_furnace_in_an_environment_map_with_light_sampling():
    """The same furnace lit by an environment map of radiance 1 everywhere, importance-sampled at every event
    and weighted against phase sampling (MIS): the weights sum to one, so the colour is still the fraction of
    paths that met the medium, up to the noise of the weights (no bias: the means agree to 0.5 %)."""
    env = Environment(kind="map", image=np.ones((16, 32, 3), np.float32))
    scene, cam = _furnace(env)
    pt = PathTracer(scene, cam, (24, 24))
    im = pt.step(64)
    hits = pt.acc[..., 3] / pt.spp
    rgb = im.rgba[..., :3]
    assert hits.max() > 0.9
    assert abs(rgb.mean() - hits.mean()) < 0.005 * hits.mean(), (rgb.mean(), hits.mean())
    assert np.abs(rgb - hits[..., None]).mean() < 0.03
