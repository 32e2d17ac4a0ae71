"""Slices in radiological display orientation, canonical reorientation and windowing."""

import numpy as np
import pytest

from volumen.core import WINDOW_PRESETS, Volume, canonical, slice_at, slice_image, window_to_uint8


def _marked_ras_volume():
    """A RAS volume whose corner voxels say where they are: value = 100*R + 10*A + S flags."""
    nz, ny, nx = 5, 6, 7
    k, j, i = np.meshgrid(np.arange(nz), np.arange(ny), np.arange(nx), indexing="ij")
    data = (100 * (i == nx - 1) + 10 * (j == ny - 1) + (k == nz - 1)).astype(np.int16)
    return Volume(data, spacing=(3.0, 2.0, 1.0))


def test_axial_display_orientation():
    v = _marked_ras_volume()
    img, sp = slice_at(v, "axial", index=2)
    assert sp == (2.0, 1.0)
    # patient's Right (max i) on the image's LEFT column, Anterior (max j) on the TOP row
    assert np.all(img[:, 0] >= 100) and np.all(img[:, -1] < 100)
    assert np.all(img[0, :] % 100 >= 10) and np.all(img[-1, :] % 100 < 10)


def test_coronal_and_sagittal_display_orientation():
    v = _marked_ras_volume()
    cor, sp = slice_at(v, "coronal", index=3)
    assert sp == (3.0, 1.0)
    assert np.all(cor[:, 0] >= 100) and np.all(cor[0, :] % 10 == 1) and np.all(cor[-1, :] % 10 == 0)
    sag, sp = slice_at(v, "sagittal", index=3)
    assert sp == (3.0, 2.0)
    # Anterior on the LEFT, Superior on top
    assert np.all(sag[:, 0] % 100 >= 10) and np.all(sag[:, -1] % 100 < 10)
    assert np.all(sag[0, :] % 10 == 1)


def test_canonical_of_lps_and_permuted_volume_keeps_world_samples():
    rng = np.random.default_rng(3)
    data = rng.integers(0, 1000, size=(4, 5, 6)).astype(np.int16)
    aff = np.zeros((4, 4))
    aff[3, 3] = 1
    aff[1, 0] = -0.5  # i -> posterior, 0.5 mm
    aff[2, 1] = 2.0   # j -> superior, 2 mm
    aff[0, 2] = -1.5  # k -> left, 1.5 mm
    aff[:3, 3] = [5, 6, 7]
    v = Volume(data, spacing=(1.5, 2.0, 0.5), affine=aff)
    assert v.orientation == "PSL"
    c = canonical(v)
    assert c.orientation == "RAS"
    assert c.spacing == (2.0, 0.5, 1.5)
    # every voxel of the canonical volume holds the original sample at the same world point
    nz, ny, nx = c.shape
    kk, jj, ii = np.meshgrid(np.arange(nz), np.arange(ny), np.arange(nx), indexing="ij")
    ijk_new = np.stack([ii.ravel(), jj.ravel(), kk.ravel()], axis=1)
    old = np.rint(v.world_to_index(c.index_to_world(ijk_new))).astype(int)
    np.testing.assert_array_equal(c.data.ravel(), v.data[old[:, 2], old[:, 1], old[:, 0]])


def test_slice_at_world_point_picks_nearest_voxel():
    v = _marked_ras_volume()
    img_w, _ = slice_at(v, "axial", world=(0.0, 0.0, 3.0 * 4 - 0.4))
    img_i, _ = slice_at(v, "axial", index=4)
    np.testing.assert_array_equal(img_w, img_i)
    with pytest.raises(IndexError):
        slice_at(v, "axial", index=5)
    with pytest.raises(ValueError, match="axial"):
        slice_at(v, "oblique")


def test_window_to_uint8_values():
    vals = np.array([-1000.0, -160.0, 40.0, 240.0, 3000.0])
    out = window_to_uint8(vals, "soft-tissue")  # level 40, width 400 -> [-160, 240]
    np.testing.assert_array_equal(out, [0, 0, 128, 255, 255])
    assert WINDOW_PRESETS["lung"].range == (-1350.0, 150.0)
    with pytest.raises(ValueError, match="bone"):
        window_to_uint8(vals, "nope")


def test_slice_image_square_pixels():
    v = _marked_ras_volume()  # axial pixels 2 mm x 1 mm
    img = slice_image(v, "axial", window=(50, 100))
    assert img.dtype == np.uint8
    assert img.shape == (12, 7)  # 6 display rows 2 mm tall -> 12 rows 1 mm tall (same 12 mm footprint)


def test_display_inverted_volume_shows_low_values_white():
    data = np.arange(2 * 3 * 4, dtype=np.int16).reshape(2, 3, 4)
    plain = slice_image(Volume(data), "axial", index=1, window=(12, 24))
    inverted = slice_image(Volume(data, meta={"display_inverted": True}), "axial", index=1, window=(12, 24))
    np.testing.assert_array_equal(inverted.astype(int), 255 - plain.astype(int))
