"""The tricubic B-spline reconstruction (``raycast._bspline``, its fast form of eight trilinear lookups) against
the B-spline basis summed over the 4 x 4 x 4 neighbourhood in numpy, scipy's un-prefiltered cubic spline, a
linear ramp it must reproduce, and finite differences of itself for its gradient."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

from volumen.render.raycast._bspline import bspline_gradient, bspline_value

SHAPE = (7, 8, 9)  # (nz, ny, nx)


def _basis(a):
    """The four cubic B-spline weights of voxels ``i - 1 .. i + 2`` at ``x = i + a``."""
    return np.array([(1 - a) ** 3, 3 * a**3 - 6 * a**2 + 4, -3 * a**3 + 3 * a**2 + 3 * a + 1, a**3]) / 6.0


def _direct(vol, x, y, z):
    """sum_{4x4x4} w_x w_y w_z vol[k, j, i], indices clamped to the volume (its edge values extended)."""
    nz, ny, nx = vol.shape
    ix, iy, iz = (int(np.floor(c)) for c in (x, y, z))
    wx, wy, wz = _basis(x - ix), _basis(y - iy), _basis(z - iz)
    ii = np.clip(np.arange(ix - 1, ix + 3), 0, nx - 1)
    jj = np.clip(np.arange(iy - 1, iy + 3), 0, ny - 1)
    kk = np.clip(np.arange(iz - 1, iz + 3), 0, nz - 1)
    block = vol[np.ix_(kk, jj, ii)].astype(float)
    return float(np.einsum("k,j,i,kji->", wz, wy, wx, block))


def _random(rng):
    """Random int16 samples in [-100, 100]: int16 as the phantoms (the ray caster samples signed integers in
    place), so these tests compile the functions the B-spline kernels of the picture tests call."""
    return rng.integers(-100, 101, SHAPE).astype(np.int16)


def _points(rng, n, lo=0.0):
    """``n`` random (x, y, z) index positions in [lo, size - 1 - lo] per axis."""
    hi = np.array(SHAPE[::-1], float) - 1 - lo
    return lo + rng.random((n, 3)) * (hi - lo)


def test_bspline_reproduces_a_linear_ramp():
    """The cubic B-spline reproduces linear functions: away from the border (where the edge is extended, not the
    ramp) every sample is the ramp's value within 1e-5 (values up to ~90), its gradient the ramp's within 1e-5."""
    z, y, x = np.mgrid[: SHAPE[0], : SHAPE[1], : SHAPE[2]].astype(float)
    vol = (2 * x - 3 * y + 5 * z + 40).astype(np.int16)
    pts = _points(np.random.default_rng(1), 200, lo=1.0)
    got = np.array([bspline_value(vol, *p) for p in pts])
    want = 2 * pts[:, 0] - 3 * pts[:, 1] + 5 * pts[:, 2] + 40
    err = np.abs(got - want).max()
    print(f"ramp: largest error {err:.2e}")
    assert err <= 1e-5
    g = np.array([bspline_gradient(vol, *p) for p in pts])
    np.testing.assert_allclose(g, np.broadcast_to([2.0, -3.0, 5.0], g.shape), atol=1e-5)


def test_bspline_matches_the_basis_sum_and_scipy():
    """Random data, random points over the whole volume (border included): the fast form equals the basis sum
    over the 4^3 neighbourhood within 1e-5, and scipy's ``map_coordinates(order=3, prefilter=False,
    mode='nearest')`` (the same approximating spline, an independent implementation) too."""
    rng = np.random.default_rng(2)
    vol = _random(rng)
    pts = _points(rng, 300)
    got = np.array([bspline_value(vol, *p) for p in pts])
    direct = np.array([_direct(vol, *p) for p in pts])
    sp = ndimage.map_coordinates(vol.astype(float), pts[:, ::-1].T, order=3, prefilter=False, mode="nearest")
    e_direct, e_scipy = np.abs(got - direct).max(), np.abs(got - sp).max()
    print(f"fast form vs basis sum {e_direct:.2e}, vs scipy {e_scipy:.2e}")
    assert e_direct <= 1e-5 and e_scipy <= 1e-5
    # and it never leaves the range of its 4^3 neighbourhood (no overshoot: the skipping bounds hold)
    assert got.min() >= vol.min() - 1e-6 and got.max() <= vol.max() + 1e-6


def test_bspline_gradient_matches_finite_differences():
    """The gradient (24 trilinear lookups) against central differences of the value (h = 1e-4 voxel, the spline
    being twice continuously differentiable: truncation ~1e-7 on values of +-100), within 1e-5 per component,
    border included."""
    rng = np.random.default_rng(3)
    vol = _random(rng)
    h = 1e-4
    worst = 0.0
    for p in _points(rng, 100):
        g = np.array(bspline_gradient(vol, *p))
        fd = np.array([(bspline_value(vol, *(p + h * e)) - bspline_value(vol, *(p - h * e))) / (2 * h)
                       for e in np.eye(3)])
        worst = max(worst, float(np.abs(g - fd).max()))
    print(f"gradient vs finite differences: largest difference {worst:.2e}")
    assert worst <= 1e-5


@pytest.mark.parametrize("x", [0.0, 3.0, 3.999999, 8.0])
def test_bspline_at_knots_and_edges(x):
    """At a knot the value is (v[i-1] + 4 v[i] + v[i+1]) / 6 per axis (edges extended): checked along x on a
    volume constant in y and z."""
    row = np.array([0, 2, 1, 5, -3, 4, 1, 7, 2])
    vol = np.broadcast_to(row, SHAPE).astype(np.int16).copy()
    assert bspline_value(vol, x, 3.3, 2.7) == pytest.approx(_direct(vol, x, 3.3, 2.7), abs=1e-5)
