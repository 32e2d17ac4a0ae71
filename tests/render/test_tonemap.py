"""The display transform: the tone curve and sRGB encoding against their published formulas, the
metered exposure, and ``tonemap="linear"`` giving the pictures of before the transform bit for bit."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tests.render import linear_scenes
from volumen.core import Display, Image
from volumen.core._tonemap import MIDDLE_GREY, aces, aces_inverse, meter, srgb_encode
from volumen.render import render

GOLDEN = Path(__file__).parent / "linear_pictures.npz"


def test_aces_is_narkowicz_fit():
    """Narkowicz (2015), "ACES Filmic Tone Mapping Curve": x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14),
    saturated to [0, 1]; its inverse undoes it below 1."""
    x = np.array([0.0, 0.01, 0.18, 0.5, 1.0, 2.0, 4.0, 16.0])
    want = np.clip(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0)
    np.testing.assert_allclose(aces(x), want, rtol=0, atol=1e-15)
    assert aces(1.0) == pytest.approx(2.54 / 3.16, abs=1e-12)  # the curve's value at 1: 0.8038
    assert np.all(np.diff(aces(np.linspace(0, 10, 1000))) >= 0)
    for y in (0.01, 0.18, 0.5, 0.9):
        assert aces(aces_inverse(y)) == pytest.approx(y, abs=1e-12)


def test_srgb_encoding_is_iec_61966_2_1():
    """12.92 x below 0.0031308, 1.055 x^(1/2.4) - 0.055 above: continuous there, 0.18 -> 0.4614, 1 -> 1."""
    x = np.array([0.0, 0.001, 0.0031308, 0.01, 0.18, 0.5, 1.0])
    want = np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)
    np.testing.assert_allclose(srgb_encode(x), want, atol=1e-15)
    assert srgb_encode(0.18) == pytest.approx(0.46136, abs=1e-5)
    assert srgb_encode(1.0) == pytest.approx(1.0, abs=1e-12)


def test_metering_shows_the_subjects_median_as_middle_grey():
    rng = np.random.default_rng(0)
    rgba = np.zeros((40, 40, 4), np.float32)
    a = np.where(rng.random((40, 40)) < 0.6, 0.9, 0.0)
    rgba[..., 3] = a
    rgba[..., :3] = (rng.lognormal(0.0, 0.5, (40, 40)) * a)[..., None] * 0.7  # grey, premultiplied
    img = Image(rgba=rgba, depth=np.zeros((40, 40)), display=Display(tonemap="aces"))
    shown = img.to_uint8(background=(0, 0, 0)) / 255.0
    subject = a > 0.5
    straight = shown[..., 0][subject] / 0.9  # background black: the shown colour is alpha x the curve's
    assert np.median(straight) == pytest.approx(srgb_encode(MIDDLE_GREY), abs=2 / 255)
    assert meter(np.zeros((4, 4, 4))) == 0.0  # nothing drawn: no exposure
    ev = 1.5
    fixed = Image(rgba=rgba, depth=np.zeros((40, 40)), display=Display(tonemap="aces", exposure=ev)).to_uint8()
    want = np.rint(np.clip(0.9 * srgb_encode(aces(2 ** ev * rgba[..., :3] / 0.9)), 0, 1) * 255)
    np.testing.assert_array_equal(fixed[subject], want[subject].astype(np.uint8))


def test_auto_tonemaps_the_lit_models_only():
    assert Display().resolved("pathtrace").tonemap == "aces"
    assert Display().resolved("shadows", "isosurface").tonemap == "aces"
    for shading in ("none", "headlight"):
        assert Display().resolved(shading).tonemap == "linear"
    assert Display().resolved("shadows", "mip").tonemap == "linear"
    with pytest.raises(ValueError, match="tonemap"):
        Display(tonemap="reinhard")


@pytest.fixture(scope="module")
def golden():
    return dict(np.load(GOLDEN))


def test_linear_display_gives_the_pictures_of_before_bit_for_bit(golden):
    """Every shading (with and without lights), isosurface and MIP: ``tonemap="linear"`` with the uniform
    environment of before writes the same bytes as the code before the display transform (commit acb0293)."""
    new = linear_scenes.pictures(linear_scenes.render_linear, linear_scenes.scenes())
    assert set(new) == set(golden)
    for name, pic in new.items():
        np.testing.assert_array_equal(pic, golden[name], err_msg=name)


def test_unlit_pictures_are_unchanged_by_default(golden):
    """The models ``auto`` leaves linear (no shading, headlight, MIP) draw as before with no setting at all."""
    scenes = {k: v for k, v in linear_scenes.scenes().items() if k.split("/")[1:2] in (["none"], ["headlight"])
              or k == "mip"}
    new = linear_scenes.pictures(render, scenes)
    for name, pic in new.items():
        np.testing.assert_array_equal(pic, golden[name], err_msg=name)
