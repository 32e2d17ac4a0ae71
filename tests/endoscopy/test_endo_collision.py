"""Collision detection: the eye keeps its safety margin from the wall, stops at it, and slides along it.

The 0.5 mm tolerances are checked on an analytic curved tube (a torus, conftest), whose distance to
the wall is exact; the phantom's voxels (2.5 mm) cannot give an exact wall. On the phantom's colon
the random walk is checked against its ground-truth lumen instead.
"""

import numpy as np
import pytest

from tests.endoscopy.endo_helpers import TORUS_R, TORUS_RC, torus_wall_distance
from volumen.endoscopy import Collider, WallField

MARGIN = 2.0


@pytest.fixture(scope="module")
def torus_collider(torus):
    return Collider(WallField.from_threshold(torus, 0.0), margin=MARGIN, max_length=20.0)


def test_random_moves_keep_the_margin(torus_collider):
    """10,000 random moves (random direction, 0..15 mm) from wherever the last one ended."""
    rng = np.random.default_rng(7)
    p = np.array([TORUS_RC, 0.0, 0.0])
    blocked = slid = allowed = 0
    closest = np.inf
    for _ in range(10_000):
        m = rng.normal(size=3)
        m *= rng.uniform(0.0, 15.0) / np.linalg.norm(m)
        res = torus_collider.move(p, m)
        assert res.moved <= np.linalg.norm(m) + 1e-9
        p = res.position
        blocked += res.blocked
        slid += res.slid
        allowed += not res.blocked
        closest = min(closest, torus_wall_distance(p)[0])
    print(f"blocked {blocked}, of which slid {slid}; allowed {allowed}; closest approach {closest:.3f} mm "
          f"(margin {MARGIN} mm)")
    assert blocked > 0 and allowed > 0 and slid > 0
    assert closest >= MARGIN - 0.5


@pytest.mark.parametrize("direction", [(1, 0, 0), (0, 0, -1), (-1, 0, 1), (1, 1, 0.5)])
def test_straight_move_toward_the_wall_stops_at_the_margin(torus_collider, direction):
    """From the tube's axis straight toward the wall (in the tube's cross-section plane: no sliding)."""
    d = np.asarray(direction, float)
    p = np.array([TORUS_RC, 0.0, 0.0])
    radial = np.array([1.0, 0.0, 0.0])
    dd = d[0] * radial + np.array([0.0, 0.0, d[2]])  # keep it in the plane y = 0 (the cross-section)
    dd /= np.linalg.norm(dd)
    res = torus_collider.move(p, 30.0 * dd)
    assert res.blocked
    off_ray = res.position - p - np.dot(res.position - p, dd) * dd
    assert np.linalg.norm(off_ray) < 1.0  # head-on: nothing (or next to nothing) left to slide
    assert abs(torus_wall_distance(res.position)[0] - MARGIN) < 0.5
    assert abs(res.moved - (TORUS_R - MARGIN)) < 0.5
    # the ray itself finds the wall where it is
    assert abs(torus_collider.first_hit(p, dd, 50.0) - TORUS_R) < 0.05


def test_oblique_move_slides_along_the_wall(torus_collider):
    """45 degrees into the wall: the part along the wall goes on, the eye stays at the margin."""
    p = np.array([TORUS_RC + 6.0, 0.0, 0.0])
    res = torus_collider.move(p, [10.0, 10.0, 0.0])
    assert res.blocked and res.slid
    assert res.position[1] > 5.0  # went on along the tube
    assert torus_wall_distance(res.position)[0] >= MARGIN - 0.5
    stop = Collider(torus_collider.wall, margin=MARGIN, slide=False).move(p, [10.0, 10.0, 0.0])
    assert stop.blocked and not stop.slid and stop.position[1] < res.position[1]


def test_clearance_matches_the_exact_distance(torus_collider):
    rng = np.random.default_rng(3)
    th = rng.uniform(0, 2 * np.pi, 50)
    rr = rng.uniform(0, 9.0, 50)
    ph = rng.uniform(0, 2 * np.pi, 50)
    pts = np.stack([(TORUS_RC + rr * np.cos(ph)) * np.cos(th), (TORUS_RC + rr * np.cos(ph)) * np.sin(th),
                    rr * np.sin(ph)], axis=1)
    got = np.array([torus_collider.clearance(p, 20.0) for p in pts])
    exact = torus_wall_distance(pts)
    assert np.all(got >= exact - 0.05) and np.all(got <= exact * 1.03 + 0.05)


def test_moves_in_the_phantom_colon_stay_in_the_lumen(torso):
    """2,000 random moves inside the torso's colon (wall at -500 HU) never leave the true lumen."""
    from scipy import ndimage

    colon = torso.meta["truth"]["colon"]
    col = Collider(WallField.from_threshold(torso, -500.0), margin=3.0)
    edt = ndimage.distance_transform_edt(colon.mask, sampling=torso.spacing)
    rng = np.random.default_rng(11)
    p = colon.centerline[200].copy()
    pts, blocked = [], 0
    for _ in range(2000):
        m = rng.normal(size=3)
        res = col.move(p, m * rng.uniform(0, 10.0) / np.linalg.norm(m))
        p = res.position
        blocked += res.blocked
        pts.append(p)
    pts = np.array(pts)
    idx = torso.world_to_index(pts)[:, ::-1]
    assert colon.mask[tuple(np.rint(idx).astype(int).T)].all()
    # voxel-exact distance to the nearest non-lumen voxel centre, less half a voxel: >= margin - 1 voxel
    d = ndimage.map_coordinates(edt, idx.T, order=1) - 0.5 * max(torso.spacing)
    assert d.min() > 3.0 - max(torso.spacing)
    assert 0 < blocked < 2000


def test_bad_collider_arguments(torus):
    wall = WallField.from_threshold(torus, 0.0)
    with pytest.raises(ValueError, match="margin"):
        Collider(wall, margin=0)
    with pytest.raises(ValueError, match="lumen must be"):
        WallField.from_threshold(torus, 0.0, lumen="inside")
    with pytest.raises(ValueError, match="finite"):
        Collider(wall).move([np.nan, 0, 0], [1, 0, 0])


def test_wall_from_mask_and_from_transfer_agree_with_threshold(torus):
    """The three ways of naming the wall find it within a voxel of each other on the torus."""
    from volumen.core import TransferFunction

    p, d = np.array([TORUS_RC, 0.0, 0.0]), np.array([1.0, 0.0, 0.0])
    tf = TransferFunction(opacity=((-100.0, 0.0), (100.0, 1.0)))
    walls = [WallField.from_threshold(torus, 0.0), WallField.from_transfer(torus, tf, 0.5),
             WallField.from_mask(torus, torus.data < 0)]
    hits = [Collider(w).first_hit(p, d, 50.0) for w in walls]
    assert abs(hits[0] - TORUS_R) < 0.05 and abs(hits[1] - TORUS_R) < 0.05
    assert abs(hits[2] - TORUS_R) < 1.0
