"""The subject a default camera frames (``core.subject_corners``) and the camera fitted to it (``Camera.orbit(...,
fit="subject")``, ``core.default_camera``), against objects whose extent is known.

Bars: the subject's box lies within one sampling stride (plus a voxel) of the object's; seen from the fitted
camera, the box's corners span :data:`SUBJECT_FILL` of the picture's height, to 1 %; the volume's own framing
(``fit="volume"``) is the bounding sphere's, as before.
"""

from __future__ import annotations

import numpy as np
import pytest

from volumen.core import (
    SUBJECT_FILL,
    Camera,
    Volume,
    default_camera,
    display_range,
    subject_corners,
    subject_level,
)
from volumen.core._subject import _stride
from volumen.data import phantom


def _ct_box(shape=(60, 120, 80), lo=(10, 30, 20), hi=(40, 90, 50), spacing=(2.0, 1.0, 1.5)):
    """A CT of air with a block of soft tissue at voxel ``lo..hi`` ([z, y, x], inclusive)."""
    data = np.full(shape, -1000, np.int16)
    data[lo[0]:hi[0] + 1, lo[1]:hi[1] + 1, lo[2]:hi[2] + 1] = 40
    return Volume(data, spacing=spacing, modality="CT", units="HU")


def _index_box(volume, corners):
    ijk = volume.world_to_index(corners)
    return np.rint(ijk.min(axis=0)).astype(int), np.rint(ijk.max(axis=0)).astype(int)  # (x, y, z)


def test_the_subject_box_is_the_tissue_within_a_stride():
    vol = _ct_box()
    lo, hi = _index_box(vol, subject_corners(vol))
    step = _stride(vol.shape)
    want_lo, want_hi = np.array([20, 30, 10]), np.array([50, 90, 40])
    assert np.all(lo <= want_lo) and np.all(lo >= want_lo - step - 1), (lo, step)
    assert np.all(hi >= want_hi) and np.all(hi <= want_hi + step + 1), (hi, step)


def test_a_few_bright_voxels_in_the_air_do_not_widen_the_subject():
    vol = _ct_box()
    noisy = vol.data.copy()
    noisy[0, 0, 0] = noisy[-1, -1, -1] = noisy[0, -1, 0] = 500
    assert np.allclose(subject_corners(Volume(noisy, spacing=vol.spacing, modality="CT")), subject_corners(vol))


def test_the_level_is_above_air_in_a_ct_and_above_the_background_in_an_mri():
    assert subject_level(phantom("head", size=32)) == -500.0
    mr = phantom("mr_head", size=48)
    background = mr.data[:, :4, :4]  # a corner column: air, Rician noise
    assert np.percentile(background, 99.9) < subject_level(mr) < 0.25 * display_range(mr)[1]


def test_a_volume_with_nothing_above_the_level_or_in_colour_is_framed_whole():
    air = Volume(np.full((8, 9, 10), -1000, np.int16), modality="CT")
    assert np.array_equal(subject_corners(air), air.corners())
    rgb = Volume(np.zeros((4, 5, 6, 3), np.uint8))
    assert np.array_equal(subject_corners(rgb), rgb.corners())


def test_a_label_map_s_subject_is_every_label():
    labels = np.zeros((30, 30, 30), np.uint8)
    labels[5:10, 5:10, 5:10] = 1
    labels[20:25, 20:25, 20:25] = 200
    lo, hi = _index_box(Volume(labels), subject_corners(Volume(labels)))
    assert np.all(lo <= 5) and np.all(hi >= 24)


@pytest.mark.parametrize("view", ["anterior", "left", "superior"])
@pytest.mark.parametrize("projection", ["perspective", "orthographic"])
def test_the_fitted_camera_spans_the_subject_s_box_over_its_share_of_the_picture(view, projection):
    """Each corner of the subject's box projects inside the picture, and the farthest from the centre lies at
    SUBJECT_FILL of the half height (1 %): the near face is accounted for at its own depth."""
    vol = _ct_box(shape=(40, 300, 60), lo=(5, 10, 10), hi=(30, 290, 50), spacing=(1.5, 0.9, 0.9))
    cam = Camera.orbit(vol, view=view, projection=projection, fit="subject")
    size = (100, 100)
    colrow, _ = cam.project(subject_corners(vol), size)
    reach = np.abs(colrow - 50.0).max() / 50.0
    assert reach == pytest.approx(SUBJECT_FILL, abs=0.01), reach


def test_the_default_camera_is_the_subject_fit_and_orbit_alone_frames_the_bounding_sphere():
    head = phantom("head", size=48)
    assert default_camera(head, view="left", zoom=1.5) == Camera.orbit(head, view="left", zoom=1.5, fit="subject")
    sphere = Camera.orbit(head)
    radius = head.diagonal / 2
    assert sphere.target == pytest.approx(tuple(head.center))
    assert sphere.distance == pytest.approx(radius / np.sin(np.radians(15.0)))
    assert default_camera(head).distance < 0.85 * sphere.distance
    with pytest.raises(ValueError, match="fit must be one of"):
        Camera.orbit(head, fit="box")
