"""The renderers' one vocabulary: devices, techniques and their options, JSON round trips, old backend names."""

from __future__ import annotations

import json

import numpy as np
import pytest

from volumen.core import Camera, Scene
from volumen.render import DEVICES, TECHNIQUES, Technique, legacy_backend, option_choices, render, resolve_device


def _every_variant():
    """Each technique with its defaults and with every value of every choice option."""
    for name in TECHNIQUES:
        yield Technique(name)
        for field, choices in option_choices(name).items():
            for value in choices if isinstance(choices, tuple) else ():
                yield Technique(name, **{field: value})


def test_techniques_round_trip_through_json():
    variants = list(_every_variant())
    assert len(variants) == 3 + (2 + 3 + 2 + 5) + 2  # raycast, slicing and its 12 choices, mesh and its 2
    for tech in variants:
        again = Technique.from_dict(json.loads(json.dumps(tech.to_dict())))
        assert again == tech and again.to_dict() == tech.to_dict()
    assert Technique("slicing", Technique("slicing", planes="two-per-voxel").options, precision="uint8").to_dict()[
        "options"] == {**Technique("slicing").options.to_dict(), "planes": "two-per-voxel", "precision": "uint8"}


def test_bad_names_and_options_list_the_valid_ones():
    with pytest.raises(ValueError, match="unknown technique 'ray'; valid: raycast, slicing, mesh"):
        Technique("ray")
    with pytest.raises(ValueError, match="technique 'mesh' has no option 'precision'; valid: shading, step"):
        Technique("mesh", precision="uint8")
    with pytest.raises(ValueError, match="precision must be one of 'uint8', 'float16', 'float32'; got 'int4'"):
        Technique("slicing", precision="int4")
    with pytest.raises(ValueError, match="technique 'slicing' takes SlicingOptions, got MeshOptions"):
        Technique("slicing", Technique("mesh").options)
    with pytest.raises(ValueError, match="a technique is"):
        Technique.from_dict({"name": "mesh", "device": "gl"})
    with pytest.raises(ValueError, match="unknown device 'gpu'; valid: cpu, cuda, gl, auto"):
        resolve_device("gpu")
    with pytest.raises(ValueError, match="technique 'slicing' runs on gl \\(or auto\\), not 'cuda'"):
        resolve_device("cuda", "slicing")
    assert resolve_device("gl", "raycast") == "gl"  # the OpenGL ray caster (issue 15)


def test_devices_resolve_per_technique():
    """None is the technique's default device; auto its best usable one (no CUDA device here: the CPU)."""
    from volumen.render.cuda import cuda_available

    assert DEVICES == ("cpu", "cuda", "gl", "auto")
    assert [resolve_device(None, n) for n in TECHNIQUES] == ["cpu", "gl", "gl"]
    assert resolve_device("auto", "mesh") == "gl"
    assert resolve_device("auto", "raycast") == ("cuda" if cuda_available() else "cpu")


def test_old_backend_names_map_to_device_and_technique():
    """Every backend name of volumen 0.1 names a device and a technique with options."""
    assert legacy_backend("cpu") == ("cpu", Technique())
    assert legacy_backend("slicing-front-to-back") == ("gl", Technique("slicing", order="front-to-back"))
    assert legacy_backend("slicing-two-then-one") == ("gl", Technique("slicing", planes="two-then-one"))
    assert legacy_backend("mesh-gouraud") == ("gl", Technique("mesh", shading="gouraud"))
    with pytest.raises(ValueError, match="unknown backend 'opengl'; valid: cpu, cuda, auto, slicing"):
        legacy_backend("opengl")


def test_backend_argument_warns_and_draws_the_same_picture(ball):
    scene, cam = Scene(volume=ball), Camera.orbit(ball, azimuth=20)
    with pytest.warns(DeprecationWarning, match="use device= and technique="):
        old = render(scene, cam, (16, 12), backend="cpu")
    new = render(scene, cam, (16, 12), device="cpu", technique="raycast")
    np.testing.assert_array_equal(old.rgba, new.rgba)
    assert new.stats["renderer"] == {"device": "cpu", "technique": "raycast"}
