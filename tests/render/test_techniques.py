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
    assert resolve_device("gl", "raycast") == "gl"  # the OpenGL ray caster


def test_devices_resolve_per_technique():
    """None is the technique's default device; auto the fastest usable here (no CUDA device and OpenGL on
    llvmpipe here: the CPU)."""
    from volumen.render.cuda import cuda_available
    from volumen.render.raster import RasterUnavailable, gl_renderer

    try:
        hardware_gl = gl_renderer()[1]
    except RasterUnavailable:
        hardware_gl = False
    assert DEVICES == ("cpu", "cuda", "gl", "auto")
    assert [resolve_device(None, n) for n in TECHNIQUES] == ["cpu", "gl", "gl"]
    assert resolve_device("auto", "mesh") == "gl"
    assert resolve_device("auto", "raycast") == ("cuda" if cuda_available() else "gl" if hardware_gl else "cpu")


@pytest.mark.parametrize(("renderer", "device"), [
    ("llvmpipe (LLVM 15.0.6, 256 bits)", "cpu"), ("softpipe", "cpu"),
    ("ANGLE (Google, Vulkan 1.3.0 (SwiftShader Device (Subzero) (0x0000C0DE)), SwiftShader driver)", "cpu"),
    ("NVIDIA H100 80GB HBM3/PCIe/SSE2", "gl"), ("AMD Radeon RX 7900 XTX (radeonsi, navi31, LLVM 17.0.6)", "gl"),
    ("Mesa Intel(R) UHD Graphics 620 (KBL GT2)", "gl")])
def test_auto_ray_casts_on_opengl_only_on_a_hardware_renderer(monkeypatch, renderer, device):
    """Mesa's llvmpipe / softpipe and SwiftShader rasterize on the CPU, slower than the CPU ray caster (1.18 s
    against 0.064 s a frame on a 164x126x120 CT at 352x345): auto takes them for the CPU, and says why."""
    from volumen.render import _techniques, choose_device, raster
    from volumen.render import cuda as cuda_pkg

    monkeypatch.setattr(cuda_pkg, "cuda_available", lambda: False)
    monkeypatch.setattr(raster, "gl_renderer", lambda: (renderer, not raster.is_software_renderer(renderer)))
    chosen, why = choose_device("auto", "raycast")
    assert chosen == device and renderer in why
    assert ("software" in why) == (device == "cpu")
    assert _techniques.resolve_device("auto", "slicing") == "gl"  # slicing and mesh run on OpenGL only


def test_auto_without_opengl_is_the_cpu(monkeypatch):
    from volumen.render import choose_device, raster
    from volumen.render import cuda as cuda_pkg

    def missing():
        raise raster.RasterUnavailable("no EGL")

    monkeypatch.setattr(cuda_pkg, "cuda_available", lambda: False)
    monkeypatch.setattr(raster, "gl_renderer", missing)
    assert choose_device("auto", "raycast") == ("cpu", "no CUDA device and no OpenGL here")


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
