"""Scene and settings: validation with the valid values named, JSON round trip, volume references."""

from __future__ import annotations

import numpy as np
import pytest

from volumen.core import Clipping, ClipPlane, Isosurface, Light, Sampling, Scene, Shading, TransferFunction, Volume


def test_defaults_follow_the_design():
    sh = Shading()
    assert (sh.ambient, sh.diffuse, sh.specular) == (0.15, 0.65, 0.2)
    assert Sampling().early_termination == 0.99 and Sampling().samples_per_voxel == 1.0


def test_round_trip_and_volume_reference():
    vol = Volume(np.zeros((4, 4, 4), np.float32))
    s = Scene(volume=vol, volume_ref="data/head.nii.gz", transfer=TransferFunction.preset("ct-lung"),
              lights=(Light(position=(1, 2, 3), exponent=2, direction=(0, 1, 0)),), mode="isosurface",
              shading=Shading(mode="phong", gradient="sobel"), sampling=Sampling(jitter=False, seed=4),
              clipping=Clipping(crop=(0, 1, 0, 2, 0, 3), crop_space="world",
                                planes=(ClipPlane(point=(0, 0, 1), normal=(0, 0, 2)),)),
              isosurface=Isosurface(value=-500, color=(1, 0.5, 0)))
    d = s.to_dict()
    assert d["volume"] == "data/head.nii.gz" and "data" not in str(d["transfer"])
    back = Scene.from_json(s.to_json())
    assert back == s and back.volume is None  # the volume is not in the JSON; equality ignores it
    assert Scene.from_dict(d, volume=vol).volume is vol
    assert Scene.from_dict(d, resolve=lambda ref: ref.upper()).volume == "DATA/HEAD.NII.GZ"
    for obj in (s.shading, s.sampling, s.clipping, s.isosurface, s.lights[0]):
        assert type(obj).from_json(obj.to_json()) == obj


@pytest.mark.parametrize("make,match", [
    (lambda: Scene(mode="xray"), "composite"),
    (lambda: Shading(mode="flat"), "headlight"),
    (lambda: Shading(gradient="prewitt"), "sobel"),
    (lambda: Sampling(interpolation="cubic"), "nearest"),
    (lambda: Sampling(samples_per_voxel=0), "samples_per_voxel"),
    (lambda: Sampling(early_termination=0), "early_termination"),
    (lambda: Clipping(crop_space="mm"), "world"),
    (lambda: Clipping(crop=(1, 0, 0, 1, 0, 1)), "min <= max"),
    (lambda: Clipping(planes=[ClipPlane(point=(0, 0, 0), normal=(0, 0, 1))] * 7), "6"),
    (lambda: ClipPlane(point=(0, 0, 0), normal=(0, 0, 0)), "zero"),
    (lambda: Light(position=(0, 0, 0), intensity=-1), "intensity"),
    (lambda: Scene.from_dict({"mode": "mip", "colour": 1}), "unknown"),
    (lambda: Scene(shading="phong"), "Shading"),
])
def test_bad_settings_raise_value_error(make, match):
    with pytest.raises(ValueError, match=match):
        make()


def test_a_scene_made_with_a_volume_alone_takes_its_default_preset():
    """No transfer function named: the volume's default preset for the mode (``default_preset``), so the scene shows
    anatomy (and a label layer over it), not the 0..1 ramp that draws every CT or MRI as an opaque box."""
    from volumen.core import default_preset
    from volumen.data import phantom

    ct = phantom("head", size=32)
    mr = Volume(np.random.default_rng(0).random((8, 9, 10)).astype(np.float32) * 800, modality="MR")
    assert Scene(volume=ct).transfer == default_preset(ct) and Scene(volume=ct).transfer.name == "ct-skin-bone"
    assert Scene(volume=mr).transfer.name == "mr-default"
    assert Scene(volume=ct, mode="mip").transfer.name == "mip-gray"
    assert Scene().transfer == TransferFunction()  # no volume: the ramp
    named = TransferFunction.preset("ct-lung")
    assert Scene(volume=ct, transfer=named).transfer is named
    assert Scene.from_dict(Scene(volume=ct).to_dict(), volume=mr).transfer.name == "ct-skin-bone"  # kept as saved
