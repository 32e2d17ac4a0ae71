"""Lumen by region growing and the automatic centerline of the torso phantom's colon, against its ground truth."""

import numpy as np
import pytest

from tests.endoscopy.endo_helpers import polyline_distance
from volumen.endoscopy import Centerline, compute_centerline, lumen_mask


def test_region_growing_gives_the_colon_lumen(torso, colon_lumen):
    truth = torso.meta["truth"]["colon"].mask
    dice = 2 * np.count_nonzero(colon_lumen & truth) / (colon_lumen.sum() + truth.sum())
    assert dice > 0.98, dice  # the scanner blur moves a few boundary voxels across -500 HU


def test_seed_outside_the_lumen_is_a_clear_error(torso):
    with pytest.raises(ValueError, match="seed"):
        lumen_mask(torso, (0.0, -55.0, 0.0), max_seed_distance=3.0)  # inside the spine


def test_automatic_centerline_follows_the_truth(torso, colon_centerline):
    """Within 1 voxel (mean) and 2 voxels (max) of the truth polyline, both ways."""
    truth = torso.meta["truth"]["colon"]
    h = max(torso.spacing)
    cl = colon_centerline
    d_ct = polyline_distance(cl.points, truth.centerline) / h
    d_tc = polyline_distance(truth.centerline, cl.points) / h
    print(f"computed->truth mean {d_ct.mean():.3f} max {d_ct.max():.3f}; truth->computed mean {d_tc.mean():.3f} "
          f"max {d_tc.max():.3f} voxels")
    assert d_ct.mean() < 1.0 and d_ct.max() < 2.0
    assert d_tc.mean() < 1.0 and d_tc.max() < 2.0
    assert abs(cl.length - truth.length) < 0.03 * truth.length
    # resampled at the fixed step, with the local radius close to the truth's (mm, voxel-limited)
    assert np.allclose(np.diff(cl.arc)[:-1], 1.0, atol=1e-9) and 0 < np.diff(cl.arc)[-1] <= 1.0
    assert np.allclose(np.linalg.norm(np.diff(cl.points, axis=0), axis=1)[:-1], 1.0, atol=0.02)
    # the local radius is the inscribed ball's: a sphere one voxel smaller lies inside the true lumen,
    # one and a half voxels larger pokes out of it
    dirs = np.random.default_rng(0).normal(size=(300, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)

    def inside(q):
        idx = np.rint(torso.world_to_index(q)[:, ::-1]).astype(int)
        return truth.mask[tuple(idx.T)]

    for p, r in zip(cl.points[::10], cl.radius[::10], strict=True):
        assert inside(p + (r - h) * dirs).all()
        assert not inside(p + (r + 1.5 * h) * dirs).all()


def test_centerline_between_given_points(torso, colon_lumen):
    truth = torso.meta["truth"]["colon"]
    a, b = truth.centerline[100], truth.centerline[300]
    cl = compute_centerline(torso, colon_lumen, a, b, step=2.0)
    h = max(torso.spacing)
    assert np.linalg.norm(cl.points[0] - a) < h and np.linalg.norm(cl.points[-1] - b) < h
    assert polyline_distance(cl.points, truth.centerline).max() < 2 * h
    assert np.allclose(np.diff(cl.arc)[:-1], 2.0)


def test_rotation_minimizing_frame_does_not_twist():
    """On a planar arc started with the plane's normal, the RMF normal stays the plane normal (exact)."""
    th = np.linspace(0, np.pi, 400)
    pts = np.stack([30 * np.cos(th), 30 * np.sin(th), np.zeros_like(th)], axis=1)
    arc = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))])
    t, n, b = Centerline(pts, np.ones(len(pts)), arc).frames((0, 0, 1))
    assert np.allclose(n, [0, 0, 1], atol=1e-9)
    assert np.allclose(np.einsum("ij,ij->i", t, n), 0, atol=1e-9)
    assert np.allclose(np.linalg.norm(b, axis=1), 1)


def test_centerline_json_round_trip(colon_centerline):
    back = Centerline.from_json(colon_centerline.to_json())
    assert np.array_equal(back.points, colon_centerline.points)
    assert np.array_equal(back.radius, colon_centerline.radius)
    with pytest.raises(ValueError, match="unknown Centerline fields"):
        Centerline.from_dict({**colon_centerline.to_dict(), "colour": 1})
