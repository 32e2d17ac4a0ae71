"""Every mode x shading renders the ball where it is and nothing where it is not."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from volumen.core import MODES, SHADINGS, Camera, Image, Isosurface, Light, Scene, Shading, TransferFunction
from volumen.render import render, render_volume

SIZE = (48, 48)


@pytest.mark.parametrize("mode,shading", list(itertools.product(MODES, SHADINGS)))
def test_every_mode_and_shading(ball, mode, shading, render_dir):
    lo, hi = ball.value_range()
    tf = (TransferFunction.preset("mip-gray", value_range=(lo, hi)) if mode in ("mip", "minip", "average")
          else TransferFunction(color=((-1000, 1, 1, 1), (1000, 1, 0.8, 0.6)),
                                opacity=((-1000, 0), (0, 0.1), (1000, 0.8))))
    lights = (Light(position=tuple(np.asarray(ball.center) + [60, 80, 40])),)
    scene = Scene(volume=ball, mode=mode, transfer=tf, shading=Shading(mode=shading), lights=lights,
                  isosurface=Isosurface(value=0.0))
    cam = Camera.anatomical(ball, "anterior", projection="orthographic")
    im = render(scene, cam, SIZE)
    im.save(render_dir / f"ball_{mode}_{shading}.png")
    a = im.rgba[..., 3]
    (c, r), _ = cam.project(ball.center, SIZE)
    centre = a[int(r), int(c)]
    corners = [a[0, 0], a[0, -1], a[-1, 0], a[-1, -1]]  # outside the volume's box (bounding-sphere framing)
    assert all(x == 0 for x in corners)
    assert np.all(np.isinf(im.depth[0, :])) and np.all(im.rgba[0] == 0)
    assert np.all(im.rgba >= 0) and np.all(a <= 1)
    if im.display.tonemap == "linear":  # premultiplied colour within its opacity
        assert np.all(im.rgba[..., :3] <= a[..., None] + 1e-6)
    else:  # high dynamic range radiance (the tone curve maps it), none where no ray met the medium
        assert np.all(im.rgba[a == 0, :3] == 0)
    if mode in ("composite", "isosurface"):
        assert centre > 0.9
        # the ball's edge: alpha falls off outside its radius (12 voxels) within the box
        (c2, r2), _ = cam.project(np.asarray(ball.center) + [0, 0, 16.5], SIZE)
        assert a[int(r2), int(c2)] < 0.05
        assert im.depth[int(r), int(c)] < cam.distance
        rgb = im.rgba[int(r), int(c), :3]
        assert rgb.max() > 0.1  # lit or emissive, never black
    else:
        assert centre == 1.0
        expected = {"mip": 1000.0, "minip": -1000.0}.get(mode)
        v = im.value[int(r), int(c)]
        if expected is not None:
            assert abs(v - expected) < 5
        else:  # mean along the central ray: the ball covers 24 of 39 mm
            assert -1000 < v < 1000 and abs(v - (1000 * 24 - 1000 * 15) / 39) < 80


def test_render_volume_one_call(ball):
    im = render_volume(ball, preset="ct-bone", view="left", mode="composite", projection="perspective", size=(32, 24),
                       shading="headlight")
    assert isinstance(im, Image) and im.rgba.shape == (24, 32, 4) and im.depth.shape == (24, 32)
    assert im.rgba[12, 16, 3] > 0.5 and im.stats["samples"] > 0 and im.stats["rays"] == 32 * 24
    assert set(im.stats["timings"]) >= {"kernel", "tables", "total"}


def test_bad_arguments_name_valid_values(ball):
    scene = Scene(volume=ball)
    cam = Camera.anatomical(ball, "anterior")
    with pytest.raises(ValueError, match="unknown device 'opengl'; valid: cpu, cuda, gl, auto"):
        render(scene, cam, (8, 8), device="opengl")
    with pytest.raises(ValueError, match="unknown technique 'splatting'; valid: raycast, slicing, mesh"):
        render(scene, cam, (8, 8), technique="splatting")
    with pytest.raises(ValueError, match="technique 'raycast' has no option 'precision'; valid: none"):
        render(scene, cam, (8, 8), precision="uint8")
    with pytest.raises(ValueError, match="technique 'slicing' runs on gl"):
        render(scene, cam, (8, 8), device="cpu", technique="slicing")
    with pytest.raises(ValueError, match="composite"):
        Scene(volume=ball, mode="xray")
    with pytest.raises(ValueError, match="volume"):
        render(Scene(), cam, (8, 8))
    with pytest.raises(ValueError, match="width"):
        render(scene, cam, (0, 8))


def test_image_to_uint8_and_save(tmp_path):
    rgba = np.zeros((2, 3, 4), np.float32)
    rgba[0, 0] = (0.25, 0.1, 0.0, 0.5)  # premultiplied
    im = Image(rgba=rgba, depth=np.full((2, 3), np.inf, np.float32))
    out = im.to_uint8(background=(1.0, 1.0, 1.0))
    assert out.shape == (2, 3, 3) and tuple(out[0, 0]) == (191, 153, 128) and tuple(out[1, 1]) == (255, 255, 255)
    straight = im.to_uint8(background=None)
    assert tuple(straight[0, 0]) == (128, 51, 0, 128)
    assert im.to_uint8(encoding="srgb")[0, 0, 0] == 137  # sRGB curve: 0.25 linear -> 0.537
    assert im.to_uint8()[0, 0, 0] == 64
    im.save(tmp_path / "a.png")
    from PIL import Image as PILImage

    assert PILImage.open(tmp_path / "a.png").size == (3, 2)
