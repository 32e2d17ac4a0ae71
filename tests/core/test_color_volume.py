"""Colour volumes (R, G, B channel last): validation, luminance, geometry, slicing and resampling."""

import numpy as np
import pytest

from volumen.core import Volume, canonical, montage, slice_at, slice_image


def _rgb_volume(affine=None):
    """(4, 5, 6, 3) uint8: red grows with i (column), green with j (row), blue with k (slice)."""
    nz, ny, nx = 4, 5, 6
    k, j, i = np.meshgrid(np.arange(nz), np.arange(ny), np.arange(nx), indexing="ij")
    data = np.stack([40 * i, 50 * j, 60 * k], axis=-1).astype(np.uint8)
    return Volume(data, spacing=(3.0, 2.0, 1.0), affine=affine)


def test_color_volume_shape_and_flag():
    v = _rgb_volume()
    assert v.is_color and v.shape == (4, 5, 6) and v.data.shape == (4, 5, 6, 3)
    assert not Volume(np.zeros((2, 3, 4))).is_color
    assert "rgb" in repr(v)
    np.testing.assert_allclose(v.center, [2.5, 4.0, 4.5])  # grid centre, channel axis not counted


@pytest.mark.parametrize("shape", [(2, 3, 4, 4), (2, 3, 4, 1), (2, 3), (2, 3, 4, 3, 1)])
def test_other_channel_counts_are_refused(shape):
    with pytest.raises(ValueError, match="colour"):
        Volume(np.zeros(shape))


def test_luminance_is_rec601_and_scalar_passthrough():
    v = _rgb_volume()
    lum = v.luminance()
    assert lum.shape == v.shape and lum.dtype == np.float32
    d = v.data.astype(float)
    np.testing.assert_allclose(lum, 0.299 * d[..., 0] + 0.587 * d[..., 1] + 0.114 * d[..., 2], rtol=1e-6)
    s = Volume(np.arange(24, dtype=np.int16).reshape(2, 3, 4))
    np.testing.assert_array_equal(s.luminance(), s.data.astype(np.float32))


def test_color_slices_keep_channels_in_display_orientation():
    v = _rgb_volume()
    img, sp = slice_at(v, "axial", index=2)
    assert img.shape == (5, 6, 3) and sp == (2.0, 1.0)
    # axial: patient's Right (max i, most red) on the left column, Anterior (max j, most green) on top
    assert img[0, 0, 0] == 200 and img[0, -1, 0] == 0 and img[0, 0, 1] == 200 and img[-1, 0, 1] == 0
    assert np.all(img[..., 2] == 120)
    out = slice_image(v, "axial", index=2, square_pixels=False)
    np.testing.assert_array_equal(out, img)  # 8-bit colour is shown as stored
    sq = slice_image(v, "coronal", index=1)  # 4 slices of dz = 3 mm, dx = 1: rows stretched x3
    assert sq.shape == (12, 6, 3) and sq.dtype == np.uint8
    assert montage(v).shape[2] == 3


def test_canonical_color_volume_keeps_world_samples():
    lps = np.diag([-1.0, -2.0, 3.0, 1.0])
    v = _rgb_volume(affine=lps)
    c = canonical(v)
    assert c.is_color and c.orientation == "RAS"
    for ijk in [(0, 0, 0), (5, 4, 3), (2, 1, 3)]:
        w = v.index_to_world(ijk)
        ci, cj, ck = np.rint(c.world_to_index(w)).astype(int)
        np.testing.assert_array_equal(c.data[ck, cj, ci], v.data[ijk[2], ijk[1], ijk[0]])


def test_color_resample_crop_and_with_data():
    v = _rgb_volume()
    r = v.resample(1.0)
    assert r.is_color and r.shape == (10, 9, 6) and r.dtype == np.uint8
    # linear channels interpolate exactly: red = 40 i, blue = 60 k = 60 * z_mm / 3 at 1 mm steps
    np.testing.assert_array_equal(r.data[:, 0, :, 0], np.broadcast_to(40 * np.arange(6), (10, 6)))
    np.testing.assert_array_equal(r.data[:, 0, 0, 2], np.rint(20 * np.arange(10)))
    c = v.crop(z=(1, 3), x=(2, 5))
    assert c.is_color and c.shape == (2, 5, 3)
    np.testing.assert_allclose(c.origin, v.index_to_world([2, 0, 1]))
    mask = v.with_data(v.luminance() > 100)
    assert not mask.is_color and mask.shape == v.shape
