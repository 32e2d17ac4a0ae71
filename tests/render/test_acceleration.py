"""Early ray termination and empty-space skipping change no pixel by more than 1e-3 and take fewer samples.

Early termination at opacity ``e`` can change a pixel by at most ``1 - e`` (what the rest of
the ray could still add), so it is tested at 0.999; skipping keeps the same samples
wherever anything is visible, so it changes nothing (tested to 1e-6).
"""

from __future__ import annotations

import numpy as np
import pytest

from tests.render.render_helpers import sphere_volume
from volumen.core import Camera, Isosurface, Sampling, Scene, Shading, TransferFunction, Volume
from volumen.render import render


@pytest.fixture(scope="module")
def shells():
    # a small dense ball inside a larger faint shell, with empty space around
    vol = sphere_volume(n=56, radius=10.0, inside=1000.0, outside=-1000.0)
    d = vol.data.copy()
    z, y, x = np.mgrid[:56, :56, :56]
    r = np.sqrt((x - 27.5) ** 2 + (y - 27.5) ** 2 + (z - 27.5) ** 2)
    d[(r > 18) & (r < 21)] = 200.0
    return Volume(d, modality="CT", units="HU")


TF = TransferFunction(color=((-1000, 0, 0, 0), (150, 1, 0.5, 0.3), (1000, 1, 1, 1)),
                      opacity=((-1000, 0), (100, 0), (200, 0.08), (600, 0.6), (1000, 0.9)))


def _render(vol, mode, zoom=1.3, **sampling):
    base = dict(samples_per_voxel=1.0, jitter=True, early_termination=1.0, skip_empty=False, adaptive=False)
    base.update(sampling)
    scene = Scene(volume=vol, mode=mode, transfer=TF, shading=Shading(mode="headlight"),
                  isosurface=Isosurface(value=500.0), sampling=Sampling(**base))
    return render(scene, Camera.orbit(vol, azimuth=20, elevation=15, zoom=zoom), (48, 48))


@pytest.mark.parametrize("spv, block", [(1.0, 4), (0.5, 2), (0.3, 2)])
@pytest.mark.parametrize("mode", ["composite", "isosurface", "mip", "minip"])
def test_skipping_changes_nothing(shells, mode, spv, block):
    """Empty-space skipping changes no pixel, also below one sample per voxel with small blocks (where a
    coarse step can step over the crossing block into one entirely above an isosurface's threshold)."""
    ref = _render(shells, mode, samples_per_voxel=spv)
    fast = _render(shells, mode, samples_per_voxel=spv, skip_empty=True, block_size=block)
    assert np.abs(fast.rgba - ref.rgba).max() <= 1e-6
    with np.errstate(invalid="ignore"):
        same_depth = (np.isinf(ref.depth) & np.isinf(fast.depth)) | (np.abs(ref.depth - fast.depth) <= 1e-4)
    assert same_depth.all()
    assert fast.stats["samples"] < 0.9 * ref.stats["samples"], (fast.stats["samples"], ref.stats["samples"])


def test_early_termination_bounded_change(shells):
    ref = _render(shells, "composite", zoom=3.0)
    fast = _render(shells, "composite", zoom=3.0, early_termination=0.999)
    assert np.abs(fast.rgba - ref.rgba).max() <= 1e-3
    assert fast.stats["samples"] < 0.9 * ref.stats["samples"]
    both = _render(shells, "composite", zoom=3.0, early_termination=0.999, skip_empty=True)
    assert np.abs(both.rgba - ref.rgba).max() <= 1e-3
    assert both.stats["samples"] < fast.stats["samples"]


@pytest.mark.parametrize("spv, block", [(1.0, 4), (0.3, 2)])
def test_skipping_changes_nothing_pre_integrated(shells, spv, block):
    """Pre-integration needs the sample before a skipped run (it is not ``eager``): skipping still changes no
    pixel, also where a step is longer than a block."""
    ref = _render(shells, "composite", samples_per_voxel=spv, preintegrate=True)
    fast = _render(shells, "composite", samples_per_voxel=spv, preintegrate=True, skip_empty=True, block_size=block)
    assert np.abs(fast.rgba - ref.rgba).max() <= 1e-6
    assert fast.stats["samples"] < 0.9 * ref.stats["samples"]


@pytest.mark.parametrize("view", ["left", "right"])
def test_skipping_keeps_a_last_sample_on_a_block_face(view):
    """A ray whose exit lies on a face of the skipping grid (65 voxels: the last plane, x = 64, starts block 16)
    still takes its last sample there: orthographic, no jitter, a bright plane on the far side."""
    d = np.zeros((65, 65, 65), np.float32)
    d[:, :, 64 if view == "left" else 0] = 1000.0
    vol = Volume(d, spacing=(1.0, 1.0, 1.0), modality="CT", units="HU")
    cam = Camera.orbit(vol, view=view, projection="orthographic")
    pics = []
    for skip in (False, True):
        scene = Scene(volume=vol, mode="mip", transfer=TF, shading=Shading(mode="none"),
                      sampling=Sampling(samples_per_voxel=1.0, jitter=False, skip_empty=skip))
        pics.append(render(scene, cam, (32, 32)))
    assert np.array_equal(pics[0].value, pics[1].value, equal_nan=True)
    assert np.nanmax(pics[1].value) > 0.9 * np.nanmax(pics[0].value) > 0
