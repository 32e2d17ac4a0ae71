"""Keyframe paths (Catmull-Rom + slerp, JSON, forward/backward) and the manual and guided navigators."""

import numpy as np
import pytest

from volumen.endoscopy import (
    Collider,
    Endoscope,
    GuidedNavigator,
    Keyframe,
    KeyframePath,
    ManualNavigator,
    Pose,
    WallField,
    catmull_rom,
    slerp,
)


@pytest.fixture(scope="module")
def path():
    kfs = [Keyframe((0, 0, 0), (1, 0, 0), (0, 0, 1)), Keyframe((10, 2, 0), (1, 0.3, 0), (0, 0, 1)),
           Keyframe((20, 0, 5), (0.5, -0.5, 0.2), (0, 0.2, 1)), Keyframe((25, -8, 6), (0, -1, 0), (1, 0, 1))]
    return KeyframePath(kfs, speed=10.0)


def test_spline_passes_through_the_keyframes(path):
    for i, k in enumerate(path.keyframes):
        assert np.allclose(path.position_at(float(i)), k.position, atol=1e-9)
        pose = path.pose_at_parameter(float(i))
        assert np.allclose(pose.forward, k.pose.forward, atol=1e-9)
        assert np.allclose(pose.up, k.pose.up, atol=1e-9)
    # constant speed: equal times, equal arc steps (to the table's resolution)
    pts = np.array([p.position for p in path.play(frames=50)])
    steps = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    assert steps.max() / steps.min() < 1.05
    assert abs(path.duration - path.length / 10.0) < 1e-12


def test_centripetal_catmull_rom_and_slerp_by_formula():
    # collinear, evenly spaced points: the centripetal spline is the straight line at uniform speed
    p = [np.array([x, 0.0, 0.0]) for x in (0.0, 1.0, 2.0, 3.0)]
    assert np.allclose(catmull_rom(*p, np.array([0.25, 0.5])), [[1.25, 0, 0], [1.5, 0, 0]])
    # slerp halfway between identity and 90 degrees about z is 45 degrees about z
    q = slerp([1, 0, 0, 0], [np.cos(np.pi / 4), 0, 0, np.sin(np.pi / 4)], 0.5)
    assert np.allclose(q, [np.cos(np.pi / 8), 0, 0, np.sin(np.pi / 8)])


def test_json_round_trip_and_backward_play_are_exact(path, tmp_path, torso, colon_centerline):
    f = tmp_path / "path.json"
    path.save(f)
    back = KeyframePath.load(f)
    assert back.to_dict() == path.to_dict()
    fwd = back.play(fps=5)
    rev = back.play(fps=5, reverse=True)
    assert len(fwd) == len(rev) > 10
    assert fwd == rev[::-1]  # dataclass equality: every float of every pose
    assert path.play(fps=5) == fwd
    # rendered frames of a path through the colon, forward and backward
    kp = KeyframePath.from_centerline(colon_centerline, every=10, start=100, end=140)
    kp2 = KeyframePath.from_json(kp.to_json())
    endo = Endoscope(volume=torso)
    a = [im.rgba for im in endo.frames(kp2.play(frames=4), (32, 32))]
    b = [im.rgba for im in endo.frames(kp.play(frames=4, reverse=True), (32, 32))]
    for x, y in zip(a, b[::-1], strict=True):
        assert np.max(np.abs(x - y)) <= 1e-6
    assert max(x[..., 3].mean() for x in a) > 0.9  # the wall fills the view


def test_bad_keyframe_files(tmp_path):
    f = tmp_path / "bad.json"
    f.write_text('{"keyframes": [{"position": [0, 0, 0], "direction": [0, 0, 0]}]}')
    with pytest.raises(ValueError, match="bad.json"):
        KeyframePath.load(f)
    with pytest.raises(ValueError, match="at least 2"):
        KeyframePath([Keyframe((0, 0, 0), (1, 0, 0))])


def test_manual_navigation_turns_and_moves():
    nav = ManualNavigator(Pose((0, 0, 0), (1, 0, 0), (0, 0, 1)), speed=5.0)
    nav.forward(2.0)
    assert np.allclose(nav.pose.position, (10, 0, 0))
    nav.yaw(90)  # turn left: from +x to +y with z up
    assert np.allclose(nav.pose.forward, (0, 1, 0), atol=1e-12)
    nav.pitch(90)  # look up
    assert np.allclose(nav.pose.forward, (0, 0, 1), atol=1e-12)
    nav.pitch(-90)
    nav.roll(90)
    assert np.allclose(nav.pose.forward, (0, 1, 0), atol=1e-12)
    assert np.allclose(nav.pose.up, (1, 0, 0), atol=1e-12)  # up turned toward the old right (+x)
    nav.strafe(1.0)
    assert np.allclose(np.linalg.norm(np.subtract(nav.pose.position, (10, 0, 0))), 5.0)


def test_manual_navigation_stops_at_the_wall(torus):
    from tests.endoscopy.endo_helpers import TORUS_RC, torus_wall_distance

    col = Collider(WallField.from_threshold(torus, 0.0), margin=2.5, slide=False)
    nav = ManualNavigator(Pose((TORUS_RC, 0, 0), (1, 0, 0), (0, 0, 1)), col, speed=10.0)
    for _ in range(5):
        res = nav.forward(1.0)
    assert res.blocked and abs(torus_wall_distance(nav.pose.position)[0] - 2.5) < 0.5


def test_guided_navigation_leave_and_snap_back(colon_centerline):
    cl = colon_centerline
    g = GuidedNavigator(cl, speed=10.0, arc=50.0)
    g.advance(2.0)
    assert np.allclose(g.pose.position, cl.at(70.0))
    assert np.dot(g.pose.forward, cl.tangent_at(70.0)) > 0.999
    g.steer(yaw=30.0)
    assert abs(np.degrees(np.arccos(np.dot(g.pose.forward, cl.tangent_at(70.0)))) - 30.0) < 1e-6
    g.advance(1.0)  # still advancing along the path while looking aside
    assert np.allclose(g.pose.position, cl.at(80.0))
    manual = g.leave_path()
    manual.move(right=3.0, forward=4.0)
    g.advance(5.0)  # off the path: no advance
    off = np.array(g.pose.position)
    assert np.linalg.norm(off - cl.at(80.0)) > 4.0
    g.snap_back()
    s, d = cl.project(off)
    assert g.on_path and abs(g.arc - s) < 1e-9 and np.allclose(g.pose.position, cl.at(s))
