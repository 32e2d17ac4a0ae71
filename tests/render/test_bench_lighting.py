"""The real-CT rows of ``volumen bench lighting``: the zoom at which the scan fills the picture (geometry only;
the rows themselves are timed by the benchmark, never in tests), and the moved-light row run small (what it
draws, not how fast)."""

from __future__ import annotations

import numpy as np
import pytest

from volumen.bench._lighting import filling_zoom
from volumen.core import Camera, Volume


@pytest.mark.parametrize(("shape", "spacing", "size"), [
    ((34, 393, 157), (1.5, 0.88, 0.88), (782, 415)),  # the VMTK aorta's slab: its height limits
    ((300, 512, 512), (1.0, 0.7, 0.7), (782, 415)),   # a whole CT
    ((40, 30, 200), (1.0, 1.0, 1.0), (200, 400)),     # a wide box in a tall picture: its width limits
])
def test_the_filling_zoom_puts_the_box_edge_to_edge_on_one_axis(shape, spacing, size):
    """Orthographic, where the zoom is exact (no eye to keep outside): the box's extent along the camera's
    right and up axes fits in the picture (half height ``parallel_scale``, half width that times the aspect)
    and meets it on one of them."""
    vol = Volume(np.zeros(shape, np.int16), spacing=spacing)
    zoom = filling_zoom(vol, Camera.orbit(vol, projection="orthographic"), size)
    cam = Camera.orbit(vol, zoom=zoom, projection="orthographic")
    r, u, _ = cam.basis()
    rel = vol.corners() - np.asarray(cam.target)
    fill_w = np.abs(rel @ r).max() / (cam.parallel_scale * size[0] / size[1])
    fill_h = np.abs(rel @ u).max() / cam.parallel_scale
    assert max(fill_w, fill_h) == pytest.approx(1.0, abs=1e-9) and min(fill_w, fill_h) <= 1.0 + 1e-9
    if size[0] >= size[1]:  # a landscape picture shows the whole bounding sphere at zoom 1: the box fills more
        assert zoom >= 1.0


def test_a_perspective_eye_stays_outside_the_box():
    """The VMTK aorta's slab is 345 mm deep seen from the front and 51 mm tall: filling the picture's height
    would put the eye inside it. The zoom stops with the eye 5 % beyond the box's depth."""
    vol = Volume(np.zeros((34, 393, 157), np.int16), spacing=(1.5, 0.88, 0.88))
    cam = Camera.orbit(vol, zoom=filling_zoom(vol, Camera.orbit(vol), (782, 415)))
    _, _, f = cam.basis()
    depth = np.abs((vol.corners() - np.asarray(cam.target)) @ f).max()
    assert cam.distance == pytest.approx(1.05 * depth, rel=1e-9)
    whole = Volume(np.zeros((300, 512, 512), np.int16), spacing=(1.0, 0.7, 0.7))  # a whole CT: the picture limits
    cam = Camera.orbit(whole, zoom=filling_zoom(whole, Camera.orbit(whole), (782, 415)))
    assert cam.distance > 1.5 * np.abs((whole.corners() - np.asarray(cam.target)) @ cam.basis()[2]).max()


def test_the_moved_light_row_sweeps_the_illumination_volume_every_frame():
    """``_moved_light_row``: shadows with the light 3 degrees further each frame; each timed frame sweeps its
    lattice again (its time is the row's ``build_s``), on a small abdomen."""
    from volumen.bench._lighting import _lights, _moved_light_row
    from volumen.bench._table import Table
    from volumen.core import Camera
    from volumen.data import phantom
    from volumen.render import render

    vol = phantom("abdomen", size=(46, 38, 42))
    table = Table("t", [(k, k, "s") for k in ("sweep", "volume", "viewport", "distance", "lights", "shading", "ms",
                                               "fps", "build_s")])
    said = []
    _moved_light_row(table, render, "abdomen", "ct-bone", (vol, 0.0), Camera.orbit(vol), (48, 32), 2, said.append)
    (row,) = table.rows
    assert row["shading"] == "shadows adaptive" and row["lights"] == 1 and row["ms"] > 0
    assert row["build_s"] > 0  # the timed frames swept a lattice: the light had moved
    assert "the light moved every frame" in said[0]
    a, b = _lights(vol, 1)[0], _lights(vol, 1, azimuth=3.0)[0]
    centre = np.asarray(vol.center)
    ra, rb = np.asarray(a.position) - centre, np.asarray(b.position) - centre
    assert abs(np.linalg.norm(ra) - np.linalg.norm(rb)) < 1e-9  # turned about the centre
    angle = np.degrees(np.arccos(np.clip(ra @ rb / (ra @ ra), -1, 1)))
    assert 1.0 < angle <= 3.0 + 1e-9  # by at most 3 degrees (less off the turning axis's plane)
