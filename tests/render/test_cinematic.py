"""Lit pictures with no flags: anatomy, not a box; neither dark nor burnt; denoising that pays.

The chest-like case is the torso phantom (lungs of air next to the contrast-filled aorta, ribs, spine), the
failure class reported on a contrast chest CT: shadows near black, path tracing black where one light does not
reach. Bars (the issue's): the subject (alpha > 0.5) has median display luminance in [0.25, 0.6] with under 1 %
of its pixels clipped, for ``shadows``, ``scattering`` and ``pathtrace`` with no lights given. The denoiser's
error against a reference is ``volumen bench pathtrace``'s (its table: 16 samples denoised, 256 raw, equal time).
"""

from __future__ import annotations

import numpy as np
import pytest

from volumen.cli import main
from volumen.core import Camera, Scene, Shading, TransferFunction, Volume, default_preset, hu_offset, is_ct
from volumen.data import phantom
from volumen.render import render

LUMA = np.array([0.2126, 0.7152, 0.0722])


def _shown(image):
    """(median display luminance of the subject, fraction of its pixels with a channel at 255)."""
    u8 = image.to_uint8() / 255.0
    subject = image.rgba[..., 3] > 0.5
    assert subject.mean() > 0.05
    return float(np.median((u8 @ LUMA)[subject])), float((u8[subject] >= 1.0).any(axis=-1).mean())


@pytest.fixture(scope="module")
def chest():
    return phantom("torso", size=(64, 48, 72))


@pytest.mark.parametrize("shading", ["shadows", "scattering", "pathtrace"])
def test_no_flags_lit_pictures_are_neither_dark_nor_burnt(chest, shading, output_dir):
    vol = chest
    scene = Scene(volume=vol, transfer=default_preset(vol), shading=Shading(mode=shading, pt_samples=8))
    image = render(scene, Camera.orbit(vol), (64, 64))
    image.save(output_dir / f"cinematic_chest_{shading}.png")
    median, clipped = _shown(image)
    print(f"{shading}: subject median luminance {median:.3f}, clipped {clipped * 100:.2f} %")
    assert 0.25 <= median <= 0.6 and clipped < 0.01
    assert image.display.tonemap == "aces"


def test_default_preset_from_modality_and_value_range():
    ct = phantom("head", size=16)
    assert is_ct(ct) and default_preset(ct).name == "ct-skin-bone"
    bare = Volume(ct.data, spacing=ct.spacing)  # no modality, no units: HU by its range (air to bone)
    assert bare.modality != "CT" and is_ct(bare) and hu_offset(bare) == 0.0
    stored = Volume(ct.data + 1000.0, spacing=ct.spacing, modality="CT", units="HU+1000")
    tf = default_preset(stored)
    assert hu_offset(stored) == 1000.0 and tf.name == "ct-skin-bone"
    ref = TransferFunction.preset("ct-skin-bone")  # moved by 1000 (its inner points: the ends stay anchored)
    stored_values, hu = np.array([700.0, 1300.0]), np.array([-300.0, 300.0])
    np.testing.assert_allclose(tf.evaluate(stored_values)[:, 3], ref.evaluate(hu)[:, 3])
    np.testing.assert_allclose(tf.evaluate(np.array([700.0])), ref.evaluate(np.array([-300.0])))
    mr = Volume(np.linspace(0, 900, 16 ** 3, dtype=np.float32).reshape(16, 16, 16), spacing=(1, 1, 1), modality="MR")
    assert not is_ct(mr) and default_preset(mr).name == "mr-default"
    assert default_preset(ct, "mip").name == "mip-gray"


def test_cli_says_which_preset_it_chose(tmp_path, capsys):
    assert main(["render", "phantom:head", "-o", str(tmp_path / "a.png"), "--size", "24x24"]) == 0
    out = capsys.readouterr().out
    assert "preset ct-skin-bone (chosen for CT)" in out and (tmp_path / "a.png").exists()
    assert main(["render", "phantom:head", "-o", str(tmp_path / "b.png"), "--size", "24x24", "--shading",
                 "pathtrace", "--pt-samples", "6", "--tonemap", "aces", "--exposure", "0.5"]) == 0
    out = capsys.readouterr().out
    assert "6 samples/pixel denoised" in out and "display aces" in out
    assert not list(tmp_path.glob(".*.tmp.png"))  # the first picture was written atomically, nothing left over
