"""The gl ray caster renders a colour volume as the CPU does: the voxels' RGB as emission (3-D RGB8 texture)."""

from __future__ import annotations

import numpy as np
import pytest

from volumen.core import Camera, Isosurface, Light, Sampling, Scene, Shading, TransferFunction, Volume
from volumen.render import render


@pytest.mark.parametrize("shading", ["none", "phong", "shadows"])
def test_colour_volume_gl_equals_cpu(gl, shading):
    z, y, x = np.mgrid[:24, :24, :24]
    v = np.clip(250 - 18 * np.sqrt((x - 11.5) ** 2 + (y - 11.5) ** 2 + (z - 11.5) ** 2), 0, 250)
    col = Volume(np.stack([v, 0.5 * v, 250 - v], -1).astype(np.uint8), spacing=(1, 1, 1))
    tf = TransferFunction(color=((0, 1, 1, 1), (255, 1, 1, 1)), opacity=((0, 0), (30, 0.0), (250, 0.6)))
    lights = (Light(position=tuple(np.asarray(col.center) + [60, 80, 40])),)
    scene = Scene(volume=col, transfer=tf, shading=Shading(mode=shading), lights=lights,
                  sampling=Sampling(adaptive=False))  # OpenGL samples at full rate
    cam = Camera.anatomical(col, "anterior", projection="orthographic")
    a, b = render(scene, cam, (32, 32)), render(scene, cam, (32, 32), device="gl")
    assert a.alpha.mean() > 0.1
    c = a.rgba[16, 16, :3]
    assert c.max() - c.min() > 0.05  # the voxels' colours, not the white table's
    d = np.abs(a.rgba - b.rgba)
    assert d.mean() <= 2e-4 and d.max() <= 0.01


@pytest.mark.parametrize("technique", ["slicing", "mesh"])
def test_slicing_and_mesh_draw_a_colour_volume_as_its_luminance(gl, technique):
    z, y, x = np.mgrid[:24, :24, :24]
    v = np.clip(250 - 18 * np.sqrt((x - 11.5) ** 2 + (y - 11.5) ** 2 + (z - 11.5) ** 2), 0, 250)
    col = Volume(np.stack([v, 0.5 * v, 250 - v], -1).astype(np.uint8), spacing=(1, 1, 1))
    tf = TransferFunction(color=((0, 1, 0.8, 0.6), (255, 1, 1, 1)), opacity=((0, 0), (40, 0.0), (250, 0.6)))
    scene = Scene(volume=col, transfer=tf, isosurface=Isosurface(value=100.0))  # mesh: the luminance 100 surface
    cam = Camera.anatomical(col, "anterior", projection="orthographic")
    a = render(scene, cam, (32, 32), technique=technique)
    b = render(scene.with_(volume=col.with_data(col.luminance())), cam, (32, 32), technique=technique)
    assert a.alpha.mean() > 0.05 and np.abs(a.rgba - b.rgba).max() == 0.0
