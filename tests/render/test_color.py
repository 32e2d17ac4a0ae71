"""Colour volumes: classified by luminance, emitting the voxels' own RGB (``volumen.render.raycast._color``).

Numbers: a grey colour volume (R = G = B = v, so luminance = v) renders as the
scalar volume v with a grey-ramp transfer function (colour v / 255), for every
shading model (mean |diff| <= 1e-4: the colour is interpolated per sample, the
table's colour read at the nearest of its entries); a red sphere and a blue
cube render red and blue where they project; projections show luminance.
"""

from __future__ import annotations

import numpy as np
import pytest

from tests.render.render_helpers import axis_camera, sphere_volume
from volumen.core import Camera, Light, Scene, Shading, TransferFunction, Volume
from volumen.render import render

GREY_TF = TransferFunction(color=((0, 0, 0, 0), (255, 1, 1, 1)), opacity=((0, 0), (50, 0.05), (250, 0.6)))


@pytest.fixture(scope="module")
def grey():
    """``(colour volume, scalar volume of its luminance)`` of a soft-edged ball, uint8 grey 0..250 (the scalar
    is int16, as the renderer samples 8-bit colour volumes' luminance: fixed point, the same kernels)."""
    v = np.rint(sphere_volume(n=32, radius=10, inside=250, outside=0).data).astype(np.uint8)
    col = Volume(np.repeat(v[..., None], 3, axis=-1), spacing=(1, 1, 1))
    return col, Volume(v.astype(np.int16), spacing=(1, 1, 1))


@pytest.mark.parametrize("shading", ["none", "headlight", "shadows", "scattering", "pathtrace"])
def test_grey_colour_volume_equals_scalar_render_of_its_luminance(grey, shading):
    col, sca = grey
    assert col.is_color and np.abs(sca.data - col.data[..., 0]).max() < 1e-4
    lights = (Light(position=tuple(np.asarray(sca.center) + [60, 80, 40])),)
    cam = Camera.anatomical(sca, "anterior", projection="orthographic")
    scene = Scene(volume=sca, transfer=GREY_TF, shading=Shading(mode=shading, pt_samples=2), lights=lights)
    a, b = render(scene, cam, (32, 32)), render(scene.with_(volume=col), cam, (32, 32))
    assert a.alpha.mean() > 0.05
    assert np.abs(a.rgba - b.rgba).mean() <= 1e-4


@pytest.mark.parametrize("mode", ["mip", "average"])
def test_projections_of_a_colour_volume_show_its_luminance(grey, mode):
    col, sca = grey
    scene = Scene(volume=sca, mode=mode, transfer=TransferFunction.preset("mip-gray", value_range=(0, 250)))
    cam = Camera.anatomical(sca, "anterior", projection="orthographic")
    a, b = render(scene, cam, (24, 24)), render(scene.with_(volume=col), cam, (24, 24))
    assert np.abs(a.rgba - b.rgba).max() == 0.0
    assert np.nanmax(np.abs(a.value - b.value)) <= 1e-3


def two_colour_phantom(n: int = 40) -> Volume:
    """A red ball (centre x = 11, radius 7) and a blue cube (x, y in 23..35, z in 12..28) in black, uint8 RGB."""
    z, y, x = np.mgrid[:n, :n, :n]
    rgb = np.zeros((n, n, n, 3), np.uint8)
    rgb[(x - 11) ** 2 + (y - 20) ** 2 + (z - 20) ** 2 <= 49] = (255, 0, 0)
    rgb[(x >= 23) & (x <= 35) & (y >= 23) & (y <= 35) & (z >= 12) & (z <= 28)] = (0, 0, 255)
    return Volume(rgb, spacing=(1, 1, 1))


@pytest.mark.parametrize("shading", ["none", "phong"])
def test_red_sphere_and_blue_cube_render_in_their_colours(shading, render_dir):
    vol = two_colour_phantom()
    cam, size = axis_camera(vol, "superior")  # column c <-> x index c, row r <-> y index ny - 1 - r
    tf = TransferFunction(color=((0, 1, 1, 1), (255, 1, 1, 1)), opacity=((0, 0), (10, 0.6), (255, 0.6)))
    lights = (Light(position=tuple(np.asarray(vol.center) + [0, 0, 100])),)
    im = render(Scene(volume=vol, transfer=tf, shading=Shading(mode=shading), lights=lights), cam, size)
    im.save(render_dir / f"colour_phantom_{shading}.png")
    red, blue = im.rgba[39 - 20, 11], im.rgba[39 - 29, 29]
    assert red[3] > 0.9 and blue[3] > 0.9
    # emission red / blue; Phong's specular adds the same white to every channel
    assert red[0] - max(red[1], red[2]) > 0.5 and abs(red[1] - red[2]) < 1e-6
    assert blue[2] - max(blue[0], blue[1]) > 0.5 and abs(blue[0] - blue[1]) < 1e-6
    if shading == "none":
        assert max(red[1], red[2], blue[0], blue[1]) < 1e-6
    assert im.rgba[39 - 5, 5, 3] == 0.0  # black background: luminance 0, transparent


def test_8_bit_luminance_is_sampled_as_int16_fixed_point():
    """8-bit colour: int16 samples at LUMA_STEPS per unit, within half a step of the exact luma; others float32."""
    from volumen.render.raycast._color import LUMA_STEPS, luminance_samples

    rgb = np.random.default_rng(3).integers(0, 256, size=(6, 7, 8, 3), dtype=np.uint8)
    rgb[0, 0, 0] = 255
    u, steps = luminance_samples(Volume(rgb))
    assert u.dtype == np.int16 and steps == LUMA_STEPS and u.max() == 255 * LUMA_STEPS
    exact = rgb.astype(np.float64) @ np.array([0.299, 0.587, 0.114])
    assert np.abs(u / steps - exact).max() <= 0.5 / LUMA_STEPS + 1e-4
    f, one = luminance_samples(Volume(rgb.astype(np.float32)))
    assert f.dtype == np.float32 and one == 1
