"""A scene and camera that go through JSON render the same pixels."""

from __future__ import annotations

import json

import numpy as np

from tests.render.render_helpers import sphere_volume
from volumen.core import Camera, Clipping, ClipPlane, Isosurface, Light, Sampling, Scene, Shading, TransferFunction
from volumen.render import render


def test_json_round_trip_same_objects_same_pixels():
    vol = sphere_volume(n=32, radius=10.0)
    tf = TransferFunction.preset("ct-bone").shifted(-300.0)
    tf = TransferFunction(color=tf.color, opacity=tf.opacity, gradient_opacity=((0, 0.2), (200, 1.0)), name="x")
    scene = Scene(volume=vol, volume_ref="phantom:ball", transfer=tf,
                  lights=(Light(position=(100, 80, 50), direction=(-1, -1, -0.5), exponent=3, intensity=0.8),),
                  shading=Shading(mode="phong", shininess=30, gradient="sobel"),
                  sampling=Sampling(samples_per_voxel=1.5, seed=3, block_size=4, preintegrate=True),
                  clipping=Clipping(crop=(2, 29, 0, 31, 1, 30),
                                    planes=(ClipPlane(point=(15, 15, 15), normal=(0.3, 1, 0.1)),)),
                  isosurface=Isosurface(value=120.0, color=(1, 0, 0)))
    cam = Camera.orbit(vol, azimuth=40, elevation=-10, zoom=1.2, projection="orthographic")
    text = scene.to_json()
    assert json.loads(text)["volume"] == "phantom:ball"
    seen = []
    scene2 = Scene.from_json(text, resolve=lambda ref: seen.append(ref) or vol)
    cam2 = Camera.from_json(cam.to_json())
    assert seen == ["phantom:ball"] and scene2.volume is vol
    assert scene2 == scene and cam2 == cam
    assert TransferFunction.from_json(tf.to_json()) == tf
    assert Light.from_json(scene.lights[0].to_json()) == scene.lights[0]
    a = render(scene, cam, (40, 32))
    b = render(scene2, cam2, (40, 32))
    assert a.rgba[..., 3].max() > 0.1
    np.testing.assert_array_equal(a.rgba, b.rgba)
    np.testing.assert_array_equal(a.depth, b.depth)
