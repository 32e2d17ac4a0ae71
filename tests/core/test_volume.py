"""Volume geometry and helpers against hand-computed answers."""

import numpy as np
import pytest

from volumen.core import Volume, axis_codes


def _oblique_affine(spacing_zyx=(2.5, 0.8, 0.6), angle_deg=25.0, origin=(10.0, -20.0, 30.0)):
    a = np.deg2rad(angle_deg)
    rot = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    aff = np.eye(4)
    aff[:3, :3] = rot @ np.diag(spacing_zyx[::-1])
    aff[:3, 3] = origin
    return aff


def test_default_affine_is_ras_with_spacing():
    v = Volume(np.zeros((4, 5, 6), np.int16), spacing=(3.0, 2.0, 1.0))
    assert np.array_equal(v.affine, np.diag([1.0, 2.0, 3.0, 1.0]))
    assert v.orientation == "RAS"
    lo, hi = v.bounds()
    np.testing.assert_allclose(lo, [0, 0, 0])
    np.testing.assert_allclose(hi, [5 * 1.0, 4 * 2.0, 3 * 3.0])
    np.testing.assert_allclose(v.center, [2.5, 4.0, 4.5])
    assert v.diagonal == pytest.approx(np.sqrt(5**2 + 8**2 + 9**2))


def test_world_index_round_trip_oblique():
    aff = _oblique_affine()
    v = Volume(np.zeros((5, 6, 7), np.float32), spacing=(2.5, 0.8, 0.6), affine=aff)
    ijk = np.random.default_rng(0).uniform(0, 5, size=(20, 3))
    xyz = v.index_to_world(ijk)
    np.testing.assert_allclose(xyz, (aff @ np.c_[ijk, np.ones(20)].T).T[:, :3], atol=1e-12)
    np.testing.assert_allclose(v.world_to_index(xyz), ijk, atol=1e-10)
    assert v.is_oblique


def test_spacing_comes_from_the_affine():
    """``Volume(data, affine=A)`` takes (dz, dy, dx) from A's column lengths (an oblique one too)."""
    v = Volume(np.zeros((2, 2, 2)), affine=np.diag([2.0, 3.0, 4.0, 1.0]))
    assert v.spacing == (4.0, 3.0, 2.0)
    oblique = Volume(np.zeros((5, 6, 7), np.float32), affine=_oblique_affine())
    np.testing.assert_allclose(oblique.spacing, (2.5, 0.8, 0.6), rtol=1e-12)
    assert Volume(np.zeros((2, 2, 2))).spacing == (1.0, 1.0, 1.0)


def test_spacing_must_match_affine():
    with pytest.raises(ValueError, match=r"\(dz, dy, dx\) = \(1, 1, 1\) mm disagrees with the affine's column "
                                         r"lengths \(1, 1, 2\) mm"):
        Volume(np.zeros((2, 2, 2)), spacing=(1, 1, 1), affine=np.diag([2.0, 1, 1, 1]))
    with pytest.raises(ValueError, match="3-D"):
        Volume(np.zeros((2, 2)))
    with pytest.raises(ValueError, match="positive"):
        Volume(np.zeros((2, 2, 2)), spacing=(1, 0, 1))


def test_axis_codes_lps_and_permuted():
    assert axis_codes(np.diag([-1.0, -1, 1, 1])) == "LPS"
    perm = np.zeros((4, 4))
    perm[2, 0] = 1  # i -> +z
    perm[0, 1] = -1  # j -> -x
    perm[1, 2] = 1  # k -> +y
    perm[3, 3] = 1
    assert axis_codes(perm) == "SLA"


def test_value_range_and_histogram_ignore_nonfinite():
    d = np.arange(27, dtype=np.float32).reshape(3, 3, 3)
    d[0, 0, 0] = np.nan
    d[1, 1, 1] = np.inf
    v = Volume(d)
    assert v.value_range() == (1.0, 26.0)
    counts, edges = v.histogram(bins=5)
    assert counts.sum() == 25
    assert edges[0] == 1.0 and edges[-1] == 26.0


def test_crop_keeps_world_positions():
    aff = _oblique_affine()
    data = np.random.default_rng(1).normal(size=(5, 6, 7)).astype(np.float32)
    v = Volume(data, spacing=(2.5, 0.8, 0.6), affine=aff)
    c = v.crop(z=(1, 4), y=slice(2, None), x=(3, 6))
    assert c.shape == (3, 4, 3)
    # voxel (i, j, k) of the crop is voxel (i+3, j+2, k+1) of the original, at the same world point
    np.testing.assert_allclose(c.index_to_world([1, 1, 1]), v.index_to_world([4, 3, 2]), atol=1e-12)
    assert c.data[1, 1, 1] == v.data[2, 3, 4]


def test_resample_isotropic_keeps_box_and_linear_values():
    # a linear ramp along z is reproduced exactly by trilinear resampling
    z = np.arange(6, dtype=np.float32)[:, None, None] * 10.0
    v = Volume(np.broadcast_to(z, (6, 4, 4)).copy(), spacing=(3.0, 1.0, 1.0))
    r = v.resample()
    assert r.spacing == (1.0, 1.0, 1.0)
    assert r.shape == (16, 4, 4)  # (6 - 1) * 3 / 1 + 1
    np.testing.assert_allclose(r.data[:, 0, 0], np.arange(16) * 10.0 / 3.0, atol=1e-4)
    np.testing.assert_allclose(r.bounds()[1], v.bounds()[1])
    np.testing.assert_allclose(r.origin, v.origin)


def test_resample_integer_dtype_kept():
    v = Volume(np.full((3, 3, 3), 100, np.int16), spacing=(2.0, 1.0, 1.0))
    r = v.resample(1.0)
    assert r.dtype == np.int16 and np.all(r.data == 100)


def test_derived_volumes_do_not_share_warnings():
    v = Volume(np.zeros((3, 4, 5), np.int16), meta={"warnings": ["from the file"]})
    c = v.crop(z=(0, 2))
    c.meta["warnings"].append("cropped")
    assert v.meta["warnings"] == ["from the file"] and c.meta["warnings"] == ["from the file", "cropped"]


def test_a_single_slice_is_drawn_as_its_slab():
    """A sample alone along an axis becomes two, half its spacing either side of it (any axis, any affine): the
    voxel-centre box is as thick as the slice and centred on it; a volume with no such axis is itself."""
    aff = np.array([[0.0, 0.7, 0, 10.0], [0, 0, -5.0, 20.0], [0.7, 0, 0, 30.0], [0, 0, 0, 1]])  # oblique-free, permuted
    one = Volume(np.arange(12, dtype=np.int16).reshape(1, 3, 4), affine=aff, modality="CT", units="HU")
    slab = one.slab()
    assert slab.shape == (2, 3, 4) and np.array_equal(slab.data[0], one.data[0]) and np.array_equal(slab.data[1],
                                                                                                     one.data[0])
    assert np.allclose(slab.extent, [(4 - 1) * 0.7, (3 - 1) * 0.7, 5.0]) and np.allclose(slab.center, one.center)
    assert np.allclose(slab.index_to_world([0, 0, 0]), one.index_to_world([0, 0, -0.5]))
    assert (slab.modality, slab.units, slab.spacing) == ("CT", "HU", one.spacing)
    thick = Volume(np.zeros((3, 3, 4), np.int16))
    assert thick.slab() is thick
    line = Volume(np.zeros((1, 1, 4), np.float32)).slab()
    assert line.shape == (2, 2, 4) and np.allclose(line.extent, [3, 1, 1])


def test_big_endian_samples_are_kept_in_this_machines_byte_order():
    """A big-endian array (pydicom's MR_small_bigendian.dcm gives one) is converted: the compiled kernels take only
    native arrays, and rendering one failed with a Numba typing error."""
    values = np.arange(-30, 30, dtype=np.int16).reshape(3, 4, 5)
    vol = Volume(values.astype(">i2"))
    assert vol.data.dtype.isnative and vol.data.dtype == np.int16 and np.array_equal(vol.data, values)
