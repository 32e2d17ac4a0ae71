"""Morphology with mm balls against scipy.ndimage; connected components."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

from volumen.core import Volume
from volumen.segment import (
    ball,
    binary_close,
    binary_open,
    dilate,
    erode,
    fill_holes,
    keep_components_touching,
    keep_largest_component,
    label_components,
)


def reference_ball(r: int) -> np.ndarray:
    z, y, x = np.ogrid[-r:r + 1, -r:r + 1, -r:r + 1]
    return x * x + y * y + z * z <= r * r


@pytest.fixture(scope="module")
def blobby() -> Volume:
    rng = np.random.default_rng(4)
    m = ndimage.gaussian_filter(rng.random((40, 40, 40)), 2.0) > 0.5
    m[:6], m[-6:], m[:, :6], m[:, -6:], m[:, :, :6], m[:, :, -6:] = (False,) * 6  # away from borders
    return Volume(m.astype(np.uint8), spacing=(1.0, 1.0, 1.0))


def test_ball_respects_anisotropic_spacing():
    fp = ball(4.0, (2.0, 1.0, 0.5))
    assert fp.shape == (5, 9, 17)
    assert fp[2, 4, 16] and fp[0, 4, 8] and fp[2, 0, 8] and not fp[0, 0, 8]
    assert np.array_equal(ball(2.0, (1, 1, 1)), reference_ball(2))


@pytest.mark.parametrize("radius", [1.0, 2.0])
def test_morphology_matches_scipy_on_isotropic_grid(blobby, radius):
    m = blobby.data.astype(bool)
    fp = reference_ball(int(radius))
    assert m.sum() > 1000
    assert np.array_equal(dilate(blobby, radius).data.astype(bool), ndimage.binary_dilation(m, fp))
    assert np.array_equal(erode(blobby, radius).data.astype(bool), ndimage.binary_erosion(m, fp))
    assert np.array_equal(binary_open(blobby, radius).data.astype(bool), ndimage.binary_opening(m, fp))
    assert np.array_equal(binary_close(blobby, radius).data.astype(bool), ndimage.binary_closing(m, fp))


def test_fill_holes_fills_a_hollow_ball():
    z, y, x = np.ogrid[:21, :21, :21]
    r2 = (x - 10) ** 2 + (y - 10) ** 2 + (z - 10) ** 2
    shell = Volume(((r2 <= 64) & (r2 > 25)).astype(np.uint8))
    filled = fill_holes(shell)
    assert np.array_equal(filled.data.astype(bool), r2 <= 64)


def test_close_does_not_erode_at_the_border():
    m = np.zeros((10, 10, 10), np.uint8)
    m[:, :, :3] = 1  # a slab touching the volume's border
    closed = binary_close(Volume(m), 2.0)
    assert np.array_equal(closed.data, m)


def test_components_largest_and_touching():
    data = np.zeros((12, 12, 20), np.uint8)
    data[1:4, 1:4, 1:4] = 1  # 27 voxels
    data[6:11, 6:11, 10:15] = 1  # 125 voxels
    data[1:3, 8:10, 16:18] = 1  # 8 voxels
    mask = Volume(data)
    labels, n = label_components(mask)
    assert n == 3 and labels.data.max() == 3
    assert keep_largest_component(mask).data.sum() == 125
    touching = keep_components_touching(mask, [(2, 2, 2), (16, 8, 1), (0, 11, 11)], space="voxel")
    assert touching.data.sum() == 27 + 8
