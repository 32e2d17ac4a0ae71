"""Analytic phantoms against their formulas."""

from __future__ import annotations

import numpy as np
import pytest

from volumen.data import phantom


def test_sphere_volume_within_2_percent_at_radius_20_voxels():
    vol = phantom("sphere", radius=20.0, spacing=1.0)
    t = vol.meta["truth"]
    assert t == {"kind": "sphere", "center": [0.0, 0.0, 0.0], "radius": 20.0,
                 "volume": pytest.approx(4 / 3 * np.pi * 8000), "inside": 1000.0, "outside": -1000.0}
    inside = vol.data == 1000
    assert np.all((vol.data == 1000) | (vol.data == -1000))  # sharp by default
    measured = inside.sum() * np.prod(vol.spacing)
    assert measured == pytest.approx(4 / 3 * np.pi * 20.0**3, rel=0.02)


def test_sphere_anisotropic_spacing_and_offset_center():
    vol = phantom("sphere", (48, 64, 80), radius=16.0, center=(3.0, -2.0, 5.0), spacing=(1.5, 1.0, 0.8))
    assert vol.shape == (48, 64, 80) and vol.spacing == (1.5, 1.0, 0.8)
    idx = np.argwhere(vol.data == 1000)  # (k, j, i)
    centroid = vol.index_to_world(idx[:, ::-1].mean(axis=0))
    np.testing.assert_allclose(centroid, [3.0, -2.0, 5.0], atol=0.1)
    assert len(idx) * np.prod(vol.spacing) == pytest.approx(4 / 3 * np.pi * 16.0**3, rel=0.02)


def test_sphere_antialiased_partial_volume_is_closer_than_sharp():
    r = 7.3
    exact = 4 / 3 * np.pi * r**3
    sharp = phantom("sphere", 32, radius=r)
    smooth = phantom("sphere", 32, radius=r, antialias=True)
    frac = (smooth.data.astype(float) + 1000.0) / 2000.0
    assert frac.min() >= 0 and frac.max() <= 1
    assert len(np.unique(smooth.data)) > 10  # blended edge values
    err_smooth = abs(frac.sum() - exact) / exact
    err_sharp = abs((sharp.data == 1000).sum() - exact) / exact
    assert err_smooth < 0.003
    assert err_smooth < err_sharp
    big = phantom("sphere", 64, radius=20.0, antialias=True)
    frac_big = (big.data.astype(float) + 1000.0) / 2000.0
    assert frac_big.sum() == pytest.approx(4 / 3 * np.pi * 20.0**3, rel=0.001)


@pytest.mark.parametrize("axis, spacing, n_expected", [("z", 1.0, 20), ("x", 1.0, 20), ("y", (2.0, 0.5, 1.0), 40),
                                                       ("z", (2.0, 1.0, 1.0), 10)])
def test_slab_thickness(axis, spacing, n_expected):
    vol = phantom("slab", thickness=20.0, axis=axis, spacing=spacing)
    a = "xyz".index(axis)
    inside = vol.data == 1000
    profile = inside.any(axis=tuple(ax for ax in range(3) if ax != 2 - a))
    assert profile.sum() == n_expected
    assert profile.sum() * vol.spacing[2 - a] == pytest.approx(20.0)
    assert inside.all(axis=tuple(ax for ax in range(3) if ax == 2 - a)).sum() == 0  # not filling the axis
    assert inside.sum() == n_expected * vol.data.size // vol.shape[2 - a]  # infinite across the others
    assert vol.meta["truth"]["thickness"] == 20.0 and vol.meta["truth"]["normal"][a] == 1.0


def test_slab_antialiased_integral_equals_thickness():
    vol = phantom("slab", thickness=13.3, axis="z", center=(0.0, 0.0, 0.37), antialias=True)
    column = (vol.data[:, 10, 10].astype(float) + 1000.0) / 2000.0
    assert column.sum() * vol.spacing[0] == pytest.approx(13.3, abs=0.002)
    # the centre of mass of the blended profile is the slab's centre
    z = vol.index_to_world(np.stack([np.zeros(vol.shape[0]), np.zeros(vol.shape[0]), np.arange(vol.shape[0])], 1))[:, 2]
    assert (column * z).sum() / column.sum() == pytest.approx(0.37, abs=0.02)


def test_ellipsoid_volume_and_extent():
    a, b, c = 25.0, 18.0, 12.0
    vol = phantom("ellipsoid", semi_axes=(a, b, c))
    assert vol.meta["truth"]["semi_axes"] == [a, b, c]
    inside = vol.data == 1000
    assert inside.sum() * np.prod(vol.spacing) == pytest.approx(4 / 3 * np.pi * a * b * c, rel=0.02)
    idx = np.argwhere(inside)
    world = vol.index_to_world(idx[:, ::-1])
    half_extent = (world.max(axis=0) - world.min(axis=0)) / 2
    np.testing.assert_allclose(half_extent, [a, b, c], atol=1.0)  # within a voxel along x, y, z


def test_ellipsoid_antialiased_volume():
    vol = phantom("ellipsoid", 48, semi_axes=(15.0, 10.0, 6.5), antialias=True)
    frac = (vol.data.astype(float) + 1000.0) / 2000.0
    assert frac.sum() == pytest.approx(4 / 3 * np.pi * 15.0 * 10.0 * 6.5, rel=0.01)


@pytest.mark.parametrize("name, params", [("sphere", {"radius": -1.0}), ("slab", {"axis": "w"}),
                                          ("slab", {"thickness": 0.0}), ("ellipsoid", {"semi_axes": (1, 0, 1)}),
                                          ("sphere", {"spacing": -1.0})])
def test_bad_shape_parameters(name, params):
    with pytest.raises(ValueError):
        phantom(name, **params)
