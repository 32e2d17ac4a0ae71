"""MIP, MinIP and average projections equal numpy reductions; clip planes remove exactly their half-space.

Tolerance: rays run along a voxel axis with pixel centres on voxel centres and one sample per voxel
starting at the exact entry, so samples land on voxel centres up to float rounding of positions
(~1e-6 voxel); values then agree with numpy within 1e-5 of the data range.
"""

from __future__ import annotations

import numpy as np
import pytest

from tests.render.render_helpers import axis_camera
from volumen.core import Clipping, ClipPlane, Sampling, Scene, TransferFunction, Volume
from volumen.render import render


@pytest.fixture(scope="module")
def noise():
    rng = np.random.default_rng(3)
    return Volume(np.rint(rng.uniform(-500, 1500, size=(20, 24, 16))).astype(np.int16))  # HU, as CT is stored


def _scene(vol, mode, **kw):
    lo, hi = vol.value_range()
    return Scene(volume=vol, mode=mode, transfer=TransferFunction.preset("mip-gray", value_range=(lo, hi)),
                 sampling=Sampling(samples_per_voxel=1.0, jitter=False), **kw)


REDUCE = {"mip": np.max, "minip": np.min, "average": np.mean}


@pytest.mark.parametrize("mode", ["mip", "minip", "average"])
@pytest.mark.parametrize("view", ["superior", "anterior"])
def test_projection_equals_numpy(noise, mode, view):
    cam, size = axis_camera(noise, view)
    im = render(_scene(noise, mode), cam, size)
    d = noise.data
    if view == "superior":  # rows <-> y reversed, columns <-> x
        expected = REDUCE[mode](d, axis=0)[::-1, :]
    else:  # rows <-> z reversed, columns <-> x reversed
        expected = REDUCE[mode](d, axis=1)[::-1, ::-1]
    np.testing.assert_allclose(im.value, expected, rtol=0, atol=1e-5 * 2000)
    assert np.all(im.rgba[..., 3] == 1.0)


def test_clip_planes_remove_their_half_space(noise):
    cam, size = axis_camera(noise, "superior")
    # keep x >= 5.5 (columns 6..) and z <= 9 (slices 0..9)
    planes = (ClipPlane(point=(5.5, 0, 0), normal=(1, 0, 0)), ClipPlane(point=(0, 0, 9.0), normal=(0, 0, -1)))
    im = render(_scene(noise, "mip", clipping=Clipping(planes=planes)), cam, size)
    a = im.rgba[..., 3]
    assert np.all(a[:, :6] == 0) and np.all(np.isnan(im.value[:, :6])) and np.all(np.isinf(im.depth[:, :6]))
    expected = noise.data[:10].max(axis=0)[::-1, :]
    np.testing.assert_allclose(im.value[:, 6:], expected[:, 6:], atol=1e-5 * 2000)
    # the kept part is never brighter than the whole
    full = render(_scene(noise, "mip"), cam, size)
    assert np.all(im.value[:, 6:] <= full.value[:, 6:] + 1e-3)


def test_crop_box_in_voxels_and_world(noise):
    cam, size = axis_camera(noise, "superior")
    crop = (2, 11, 3, 20, 0, 9)  # i, j, k index ranges (voxel centres)
    im = render(_scene(noise, "mip", clipping=Clipping(crop=crop)), cam, size)
    expected = noise.data[0:10, 3:21, 2:12].max(axis=0)
    got = im.value[::-1, :][3:21, 2:12]
    np.testing.assert_allclose(got, expected, atol=1e-5 * 2000)
    assert np.isnan(im.value[::-1, :][:, :2]).all() and np.isnan(im.value[::-1, :][:, 12:]).all()
    # the same box in world mm (unit spacing, origin 0): same picture
    imw = render(_scene(noise, "mip", clipping=Clipping(crop=crop, crop_space="world")), cam, size)
    np.testing.assert_array_equal(np.nan_to_num(imw.value, nan=-1), np.nan_to_num(im.value, nan=-1))


def test_the_three_projections_are_one_kernel(noise):
    """mip, minip and average run one compiled kernel (``Settings.projection`` picks the projection): after a MIP the
    other two compile nothing, and ``warm`` takes them for one job."""
    from volumen.render._warm import kernel_key
    from volumen.render.raycast._march import _trace_tiles

    cam, size = axis_camera(noise, "superior")
    render(_scene(noise, "mip"), cam, size)
    kernels = len(_trace_tiles.overloads)
    for mode in ("minip", "average"):
        assert render(_scene(noise, mode), cam, size).stats["samples"] > 0
    assert len(_trace_tiles.overloads) == kernels
    assert len({kernel_key(_scene(noise, m), cam) for m in REDUCE}) == 1
