"""Every volume's samples reach the kernels as int16 (``_precompute.int16_samples``): one compiled kernel per mode
for CT, MRI and float data. Checked against the table index each value should have, ``(x - vmin) / scale``:
exact for integers whose range spans at most 65,536 values, within half a quantization level for the rest."""

from __future__ import annotations

import numpy as np
import pytest

from volumen.render.raycast._precompute import LEVELS, NLUT, int16_samples

RNG = np.random.default_rng(7)


def _index(u, u0, ufac):
    return (u.astype(np.float64) - u0) * ufac


def _expected(x, vmin, vmax):
    return np.clip((x.astype(np.float64) - vmin) * (NLUT - 1) / (vmax - vmin), 0.0, NLUT - 1)


def _range(x):
    f = x[np.isfinite(x)] if x.dtype.kind == "f" else x
    return float(f.min()), float(f.max())


def test_int16_data_is_sampled_in_place():
    x = RNG.integers(-1024, 3000, (5, 6, 7)).astype(np.int16)
    u, u0, ufac = int16_samples(x, *_range(x))
    assert u is x
    np.testing.assert_allclose(_index(u, u0, ufac), _expected(x, *_range(x)), rtol=0, atol=1e-9)


@pytest.mark.parametrize("dtype,lo,hi", [(np.uint8, 0, 256), (np.int8, -128, 128), (np.uint16, 0, 65536),
                                         (np.uint16, 30000, 65536), (np.int32, -70000, -4465),
                                         (np.int64, 10**12, 10**12 + 65536), (np.int16, -32768, 32768)])
def test_integers_of_at_most_65536_values_are_shifted_exactly(dtype, lo, hi):
    x = RNG.integers(lo, hi, (6, 5, 9)).astype(dtype)
    x.flat[:2] = (lo, hi - 1)  # the whole span
    if dtype == np.int16:  # in place only when writable: a read-only array is copied
        x.flags.writeable = False
    u, u0, ufac = int16_samples(x, *_range(x))
    assert u.dtype == np.int16 and u is not x
    assert np.array_equal(u.astype(np.int64) - int(u.min()), x.astype(np.int64) - lo)  # shifted, nothing lost
    np.testing.assert_allclose(_index(u, u0, ufac), _expected(x, *_range(x)), rtol=0, atol=1e-9)


def test_a_strided_int16_view_is_copied_exactly():
    x = RNG.integers(-1000, 1000, (6, 8, 10)).astype(np.int16)[:, ::2, 1::3]
    u, u0, ufac = int16_samples(x, *_range(x))
    assert u.flags.c_contiguous and u.dtype == np.int16
    np.testing.assert_allclose(_index(u, u0, ufac), _expected(x, *_range(x)), rtol=0, atol=1e-9)


@pytest.mark.parametrize("dtype,span", [(np.float32, 1.0), (np.float64, 4095.0), (np.float32, 1e6),
                                        (np.int32, 3e6)])
def test_floats_and_wide_integers_are_quantized_within_half_a_level(dtype, span):
    x = (RNG.random((7, 6, 5)) * span - span / 3).astype(dtype)
    vmin, vmax = _range(x)
    u, u0, ufac = int16_samples(x, vmin, vmax)
    err = np.abs(_index(u, u0, ufac) - _expected(x, vmin, vmax))
    level = (NLUT - 1) / (LEVELS - 1)  # table entries per level: 1/16
    print(f"{np.dtype(dtype).name} over {span:g}: max error {err.max() / level:.3f} levels")
    assert err.max() <= 0.5 * level + 1e-9
    assert u.min() == -32768 and u.max() == 32767  # the range's ends are the levels' ends


def test_nan_sits_at_the_low_end_and_infinities_are_clamped():
    x = np.array([[[np.nan, -np.inf, np.inf, 2.0, 5.0]]], np.float32)
    u, u0, ufac = int16_samples(x, 2.0, 5.0)
    assert list(_index(u, u0, ufac)[0, 0]) == [0.0, 0.0, NLUT - 1, 0.0, NLUT - 1]


def test_values_outside_the_range_are_clamped_to_its_ends():
    x = np.array([[[-50.0, 0.0, 10.0, 60.0]]], np.float32)
    u, u0, ufac = int16_samples(x, 0.0, 10.0)
    np.testing.assert_allclose(_index(u, u0, ufac)[0, 0], [0.0, 0.0, NLUT - 1, NLUT - 1], atol=1e-9)


def test_steps_per_unit_scale_the_samples_units():
    """A colour volume's luminance comes with ``steps`` samples per data unit (``_color.luminance_samples``)."""
    x = np.arange(0, 256 * 128, 37, dtype=np.int32).reshape(1, 1, -1)
    vmin, vmax = 0.0, float(x.max()) / 128
    u, u0, ufac = int16_samples(x, vmin, vmax, steps=128)
    np.testing.assert_allclose(_index(u, u0, ufac), _expected(x / 128.0, vmin, vmax), rtol=0, atol=1e-9)


@pytest.mark.parametrize("dtype", [np.int16, np.uint16, np.float32])
def test_a_range_short_of_the_data_clamps_its_far_values_to_the_last_table_entry(dtype):
    """``core.table_range`` may end below the data's maximum (far outliers): the samples are then a copy (int16
    too), the values in range keep their index (exactly for integers, within half a level for floats) and those
    above sit at the last entry, never past it (the kernels' table reads are not bounds-checked)."""
    x = RNG.integers(0, 700, (6, 5, 8)).astype(dtype)
    x.flat[:3] = (0, 699, 30000)
    vmin, vmax = 0.0, 699.0 * 16.5 / 16  # not a whole number of units: the clamp still stays in the table
    u, u0, ufac = int16_samples(x, vmin, vmax, in_place=False)
    assert u is not x
    idx = _index(u, u0, ufac)
    assert idx.max() <= NLUT - 1 and idx.flat[2] >= NLUT - 1 - (NLUT - 1) / 699
    keep = x < 699.5
    level = 0.0 if dtype != np.float32 else 0.5 * (NLUT - 1) / (LEVELS - 1)
    assert np.abs(idx[keep] - _expected(x[keep], vmin, vmax)).max() <= level + 1e-9


def test_an_int16_mri_with_a_fill_far_below_is_copied_and_its_fill_sits_at_the_first_entry():
    """``core.table_range`` may start above the data's minimum (an int16 MRI whose fill outside the field of view
    is -32768): ``Prepared`` then samples a copy, not the data in place, whose fill voxels sit at table entry 0
    and never under it (the kernels' table reads are not bounds-checked), and whose tissue keeps its index
    exactly."""
    from volumen.core import Volume
    from volumen.data import fill_outside_field, phantom
    from volumen.render.raycast._cache import Prepared

    mr = fill_outside_field(phantom("mr_head", size=32), -32768.0)
    vol = Volume(mr.data.astype(np.int16), spacing=mr.spacing, modality="MR")
    p = Prepared(vol, None)
    assert p.u is not vol.data and p.vmin > -32768.0
    idx = _index(p.u, p.u0, p.ufac)
    fill = vol.data == -32768
    assert fill.any() and idx.min() == 0.0 and np.all(idx[fill] == 0.0)
    np.testing.assert_allclose(idx[~fill], _expected(vol.data[~fill], p.vmin, p.vmax), rtol=0, atol=1e-9)


def test_a_brick_holding_values_past_the_whole_volumes_table_clamps_them_in_a_copy():
    """A brick of an out-of-core volume spans the whole volume's table (``core.table_range``, which may start above
    a fill far below): one that holds the fill (``clamps``) is sampled from a copy whose fill sits at entry 0,
    not in place; one that holds none is sampled in place."""
    from volumen.render.bricked._bricks import Brick, brick_volume
    from volumen.render.raycast._cache import Prepared

    data = RNG.integers(0, 600, (8, 8, 8)).astype(np.int16)
    data[:, :, :2] = -32768
    whole = type("Whole", (), {"spacing": (1.0, 1.0, 1.0), "affine": np.eye(4)})()
    b = Brick(index=(0, 0, 0), lo=(0, 0, 0), hi=(7, 7, 7), rlo=(0, 0, 0), rhi=(8, 8, 8))
    held = Prepared(brick_volume(b, data, whole, (-2000.0, 599.0), clamps=True), None)
    assert held.u is not data
    idx = _index(held.u, held.u0, held.ufac)
    assert idx.min() == 0.0 and np.all(idx[:, :, :2] == 0.0)
    inside = data[:, :, 2:].copy()
    free = Prepared(brick_volume(b, inside, whole, (-2000.0, 599.0)), None)
    assert free.u is inside
