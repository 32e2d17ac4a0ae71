"""A chunked (OME-Zarr) volume in the notebook view: a coarse pyramid level while dragging, the full one after."""

from __future__ import annotations

import numpy as np
import pytest

import volumen
from volumen.core import Camera, Scene, TransferFunction
from volumen.notebook import REDUCED_FRACTION

pytest.importorskip("zarr", reason="the scale extra (zarr) is not installed")


def test_drag_frames_draw_a_coarse_level_and_the_final_frame_the_full_one(tmp_path, monkeypatch):
    """96 x 128 x 128 (levels 128, 64, 32 voxels on the long side) in a 128 x 128 view: the reduced drag frame
    (REDUCED_FRACTION of the side) is drawn from the level about one voxel per pixel, the final frame from
    level 0 -- and equals the bricked render of level 0 at full size; the next drag frame finds the coarse level's
    bricks in its cache."""
    from volumen.notebook._view import ViewState, draw_frame
    from volumen.scale import _interactive, render_bricked, write_synthetic

    path = tmp_path / "s.ome.zarr"
    write_synthetic(path, (96, 128, 128), chunks=32)
    vol = volumen.load(path)
    levels, images = [], []
    real = _interactive.render_bricked
    monkeypatch.setattr(_interactive, "render_bricked",
                        lambda *a, **k: levels.append(k["level"]) or images.append(real(*a, **k)) or images[-1])
    scene = Scene(volume=vol, transfer=TransferFunction.window_level(600, 500, opacity=(0.0, 0.6)))
    cam = Camera.orbit(vol, azimuth=30, elevation=20)
    state = ViewState(scene=scene, camera=cam, size=(128, 128))
    small = draw_frame(state, REDUCED_FRACTION)
    full = draw_frame(state, 1.0)
    side = round(128 * REDUCED_FRACTION)
    expected = 1 if side >= 64 else 2
    assert levels == [expected, 0]
    assert small.shape == full.shape == (128, 128, 3) and small.any()
    np.testing.assert_array_equal(full, render_bricked(path, scene, cam, (128, 128)).to_uint8())
    # dragging on: the coarse level stays open, its bricks cached: the next frame reads and prepares nothing
    draw_frame(ViewState(scene=scene, camera=Camera.orbit(vol, azimuth=45, elevation=10), size=(128, 128)),
               REDUCED_FRACTION)
    assert levels[-1] == expected and images[-1].stats["chunk_reads"] == images[-1].stats["bricks_prepared"] == 0
