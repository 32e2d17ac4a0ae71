"""Flythrough of the torso phantom's colon: the camera stays in the lumen, the polyp is where it should be."""

import json

import numpy as np
import pytest
from scipy import ndimage

from volumen.endoscopy import Endoscope, FrameLog, Keyframe, KeyframePath, Pose

SIZE = (64, 64)


def test_flythrough_never_leaves_the_lumen(torso, colon_centerline):
    """Every camera position of a 600-frame flight is inside the true lumen, at least 4 mm from its wall."""
    colon = torso.meta["truth"]["colon"]
    poses = KeyframePath.from_centerline(colon_centerline, every=10).play(frames=600)
    pts = np.array([p.position for p in poses])
    idx = torso.world_to_index(pts)[:, ::-1]
    assert colon.mask[tuple(np.rint(idx).astype(int).T)].all()
    edt = ndimage.distance_transform_edt(colon.mask, sampling=torso.spacing)
    wall = ndimage.map_coordinates(edt, idx.T, order=1) - 0.5 * max(torso.spacing)
    print(f"closest approach to the wall along the flight: {wall.min():.2f} mm")
    assert wall.min() > 4.0


def _pixel_ray(cam, col, row, size):
    """Unit direction of the ray through the centre of pixel (col, row) (the camera model of volumen.core)."""
    w, h = size
    r, u, f = cam.basis()
    half = np.tan(np.radians(cam.fov) / 2)
    d = f + (col + 0.5 - w / 2) / (h / 2) * half * r + (h / 2 - row - 0.5) / (h / 2) * half * u
    return d / np.linalg.norm(d)


def _polyp_checks(endo, poses, polyp, data_volume, size=SIZE):
    """(depth error mm, frame) for the frames where the polyp's centre projects into the view and the line of
    sight to its sphere is free (checked by marching the data with scipy, not our code)."""
    c, radius = np.asarray(polyp["center"]), polyp["radius"]
    data = data_volume.data.astype(np.float32)
    out = []
    for k, pose in enumerate(poses):
        cam = endo.camera(pose)
        (x, y), dep = cam.project(c, size)
        col, row = int(np.floor(x)), int(np.floor(y))
        if not (0 <= col < size[0] and 0 <= row < size[1] and dep > 0):
            continue
        o, d = np.asarray(pose.position), _pixel_ray(cam, col, row, size)
        b = np.dot(d, o - c)
        disc = b * b - (np.dot(o - c, o - c) - radius**2)
        if disc < 0:
            continue
        t_sphere = -b - np.sqrt(disc)  # first intersection with the polyp's sphere (exact)
        tt = np.arange(0.0, t_sphere - 1.5, 0.25)
        vals = ndimage.map_coordinates(data, data_volume.world_to_index(o + tt[:, None] * d)[:, ::-1].T, order=1)
        if np.any(vals >= -500):  # a fold hides the polyp's centre from here
            continue
        img = endo.render(pose, size)
        out.append((float(img.depth[row, col] - t_sphere), k, img))
    return out


def test_polyp_depth_in_the_flythrough(torso, colon_centerline, endo_dir):
    """Frames where the polyp's centre is in view: rendered depth = distance to the polyp's sphere within 1 mm.

    Two flights: along the centerline toward the polyp (folds hide it until the eye is near), and a
    keyframed pass between its two neighbouring folds looking at it.
    """
    pol = torso.meta["truth"]["polyp"]
    cl = colon_centerline
    endo = Endoscope(volume=torso, fov=100)
    s_p, _ = cl.project(pol["center"])
    along = KeyframePath.from_centerline(cl, every=5, start=s_p - 30, end=s_p + 2).play(frames=24)
    c = np.asarray(pol["center"])
    kfs = []
    for ds, side in ((-9, -4), (-4, 2), (1, 5), (6, -3)):
        p = cl.at(s_p + ds) + side * np.cross(cl.tangent_at(s_p + ds), pol["direction"])
        kfs.append(Keyframe(tuple(p), tuple(c - p), tuple(cl.tangent_at(s_p + ds))))
    look = KeyframePath(kfs, speed=10.0).play(frames=12)
    res_along = _polyp_checks(endo, along, pol, torso)
    res_look = _polyp_checks(endo, look, pol, torso)
    errs = np.array([e for e, _, _ in res_along + res_look])
    print(f"polyp depth errors over {len(errs)} frames: max |e| {np.abs(errs).max():.3f} mm, "
          f"mean {errs.mean():.3f} mm ({len(res_along)} along the centerline, {len(res_look)} looking at it)")
    assert len(res_look) >= 8  # along the centerline the folds hide the centre in most frames (0..2 remain)
    assert np.abs(errs).max() < 1.0
    # frames to look at: the polyp seen from the centerline and from beside it
    endo.render(along[-6], (128, 128)).save(endo_dir / "polyp_along_centerline.png")
    res_look[len(res_look) // 2][2].save(endo_dir / "polyp_close.png")
    big = endo.render(look[len(look) // 2], (256, 256))
    big.save(endo_dir / "polyp_close_256.png")
    assert big.alpha.min() > 0.99  # the wall everywhere, no hole to black


def test_flythrough_frames_and_timing_log(torso, colon_centerline, endo_dir):
    endo = Endoscope(volume=torso, fov=110, mode="composite")
    log = FrameLog()
    poses = KeyframePath.from_centerline(colon_centerline, every=10, start=20, end=220).play(frames=4)
    imgs = list(endo.frames(poses, (160, 160), log=log))
    for k, img in enumerate(imgs):
        img.save(endo_dir / f"flythrough_composite_{k}.png")
        assert img.alpha.mean() > 0.95  # the lumen is closed: every ray ends on the wall
        lum = img.to_uint8().mean(axis=2)
        assert lum.mean() > 30 and lum.std() > 5  # lit, not black, with structure (folds)
    iso = Endoscope(volume=torso).render(poses[1], (160, 160))
    iso.save(endo_dir / "flythrough_isosurface_1.png")
    assert len(log.times) == 4
    t = np.array(log.times)
    d = log.to_dict()
    assert d["weighted_mean_s"] == pytest.approx((t * t).sum() / t.sum())
    assert d["mean_s"] == pytest.approx(t.mean())
    json.dumps(d)


def test_flashlight_follows_the_camera(torso, colon_centerline):
    """Phong with the flashlight is brighter than the same scene lit by nothing but ambient light."""
    pose = KeyframePath.from_centerline(colon_centerline, every=10, start=150, end=170).pose_at(0.0)
    lit = Endoscope(volume=torso).render(pose, (32, 32))
    ambient_only = Endoscope(volume=torso, flashlight=1e6).render(pose, (32, 32))  # spot too narrow to light
    assert lit.rgba[..., :3].mean() > 2 * ambient_only.rgba[..., :3].mean()
    with pytest.raises(ValueError, match="fov"):
        Endoscope(volume=torso, fov=170)
    assert isinstance(pose, Pose)


def test_flashlight_at_the_eye_casts_no_visible_shadow(torso, colon_centerline):
    """A point flashlight exactly at the eye lights every point the eye sees along an empty (air) path, so the
    `shadows` model must give the `phong` picture on frames inside the colon. In isosurface mode the shadows'
    occluder is the drawn surface itself: at most 1% of pixels may differ by more than 1e-3 (grazing rays past
    a sub-voxel fold tip, which the shadow ray's samples meet and the view ray's samples step over), and the
    mean difference stays below 1e-3."""
    poses = KeyframePath.from_centerline(colon_centerline, every=10).play(frames=40)[10:40:10]
    for pose in poses:
        lit = Endoscope(volume=torso, shading="phong", flashlight=0.0)
        shadowed = lit.with_(shading="shadows")
        a, b = lit.render(pose, (32, 32)), shadowed.render(pose, (32, 32))
        assert a.alpha.mean() > 0.5, "the frame shows no wall"
        diff = np.abs(a.rgba - b.rgba).max(axis=2)
        assert np.mean(diff > 1e-3) <= 0.01 and diff.mean() < 1e-3
