"""Thresholds and region growing against numpy and scipy.ndimage.label."""

from __future__ import annotations

import numpy as np
import pytest

from volumen.core import Volume
from volumen.segment import region_grow, threshold


@pytest.fixture(scope="module")
def ct() -> Volume:
    rng = np.random.default_rng(0)
    data = rng.integers(-1000, 1500, size=(20, 24, 28)).astype(np.int16)
    aff = np.diag([0.7, 0.8, 2.0, 1.0])
    aff[:3, 3] = [-10.0, 5.0, 40.0]
    return Volume(data, spacing=(2.0, 0.8, 0.7), affine=aff, modality="CT", units="HU")


def test_threshold_is_exactly_the_numpy_mask(ct):
    m = threshold(ct, -200, 300)
    assert m.dtype == np.uint8 and m.shape == ct.shape
    assert np.array_equal(m.data.astype(bool), (ct.data >= -200) & (ct.data <= 300))
    assert np.array_equal(m.affine, ct.affine) and m.spacing == ct.spacing
    union = threshold(ct, ranges=[(-1000, -500), (400, 600)])
    expect = ((ct.data >= -1000) & (ct.data <= -500)) | ((ct.data >= 400) & (ct.data <= 600))
    assert np.array_equal(union.data.astype(bool), expect)
    assert np.array_equal(threshold(ct, lo=0).data.astype(bool), ct.data >= 0)
    with pytest.raises(ValueError, match="lo <= hi"):
        threshold(ct, 10, 0)


def two_blobs() -> Volume:
    """Two separate balls of value 100 in a background of 0, plus noise that stays out of range."""
    z, y, x = np.ogrid[:30, :30, :40]
    a = (z - 15) ** 2 + (y - 15) ** 2 + (x - 10) ** 2 <= 36
    b = (z - 15) ** 2 + (y - 14) ** 2 + (x - 28) ** 2 <= 49
    data = np.where(a | b, 100, 0).astype(np.float32)
    data += np.random.default_rng(3).uniform(-5, 5, data.shape).astype(np.float32)
    return Volume(data, spacing=(1.2, 1.0, 0.9))


def test_region_growing_returns_exactly_the_seeded_blob():
    from scipy import ndimage

    vol = two_blobs()
    seed_ijk = (10, 15, 15)  # (i, j, k) = (x, y, z): inside blob a
    grown = region_grow(vol, seed_ijk, lo=50, hi=150, space="voxel", connectivity=6)
    labels, n = ndimage.label((vol.data >= 50) & (vol.data <= 150))
    assert n == 2
    expect = labels == labels[15, 15, 10]
    assert np.array_equal(grown.data.astype(bool), expect)
    assert grown.meta["voxels"] == expect.sum()
    # the same seed in world mm, and the tolerance form, give the same mask
    world = vol.index_to_world(seed_ijk)
    assert np.array_equal(region_grow(vol, world, lo=50, hi=150).data, grown.data)
    assert np.array_equal(region_grow(vol, world, tolerance=40).data, grown.data)
    both = region_grow(vol, [seed_ijk, (28, 14, 15)], lo=50, hi=150, space="voxel")
    assert both.data.sum() == (labels > 0).sum()


def test_6_and_26_connectivity_differ_on_diagonal_contact():
    data = np.zeros((10, 10, 10), np.int16)
    data[2:5, 2:5, 2:5] = 1  # A: 27 voxels, the seed's
    data[2:5, 0:2, 2:5] = 1  # 18 voxels sharing a face with A
    data[5:8, 2:5, 5:8] = 1  # 27 voxels sharing only an edge with A
    data[5:8, 5:8, 0:2] = 1  # 18 voxels sharing only a corner with A
    vol = Volume(data)
    seed = (3, 3, 3)
    n6 = region_grow(vol, seed, lo=1, hi=1, connectivity=6, space="voxel").data.sum()
    n18 = region_grow(vol, seed, lo=1, hi=1, connectivity=18, space="voxel").data.sum()
    n26 = region_grow(vol, seed, lo=1, hi=1, connectivity=26, space="voxel").data.sum()
    assert (n6, n18, n26) == (45, 72, 90)
    with pytest.raises(ValueError, match="connectivity"):
        region_grow(vol, seed, lo=1, hi=1, connectivity=8, space="voxel")


def test_region_growing_errors_name_the_problem():
    vol = two_blobs()
    with pytest.raises(ValueError, match="outside the volume"):
        region_grow(vol, (500.0, 0.0, 0.0), lo=50, hi=150)
    with pytest.raises(ValueError, match="no seed"):
        region_grow(vol, (0, 0, 0), lo=50, hi=150, space="voxel")
    with pytest.raises(ValueError, match="space"):
        region_grow(vol, (0, 0, 0), lo=50, hi=150, space="mm")
