"""The unfolded view: exact radii on an analytic tube, the phantom's polyp at its known arc and angle."""

import numpy as np
from scipy import ndimage

from volumen.core import Volume
from volumen.endoscopy import Centerline, WallField, unfold


def test_unfolded_straight_tube_has_its_radius_everywhere():
    """A cylinder of radius 9 mm along x (data = 100 HU per mm of signed distance): every ray meets it at 9 mm."""
    z, y, x = np.mgrid[:31, :31, :41].astype(float)
    d = np.hypot(y - 15, z - 15)
    vol = Volume((100.0 * (d - 9.0)).astype(np.float32), spacing=(1.0, 1.0, 1.0))
    pts = np.stack([np.linspace(5, 35, 31), np.full(31, 15.0), np.full(31, 15.0)], axis=1)
    cl = Centerline(pts, np.full(31, 9.0), np.linspace(0, 30, 31))
    u = unfold(WallField.from_threshold(vol, 0.0), cl, angles=72, normal=(0, 0, 1))
    assert u.radius.shape == (72, 31) and u.rgb.shape == (72, 31, 3)
    assert np.abs(u.radius - 9.0).max() < 0.05
    # angle 0 is the frame's normal (+z), 90 degrees N x T = z cross x = +y
    assert u.angle_of(10.0, (0, 0, 1)) == 0.0 and abs(u.angle_of(10.0, (0, 1, 0)) - 90.0) < 1e-9
    # head-on light: diffuse 1 everywhere -> one colour
    assert np.ptp(u.rgb[..., 0]) < 0.02


def test_unfolded_view_is_the_wall_seen_from_inside_not_mirrored(colon_centerline, torso):
    """Facing the wall at angle theta with the path running to the right (+T) in the picture, the inside view's
    up is T x e(theta) (right = forward x up). One row up in the unfolded picture must go that way too, at
    every column and angle: a mirrored picture would flip left/right against the flythrough."""
    cl = colon_centerline
    u = unfold(WallField.from_threshold(torso, -500.0), cl, angles=36, step=20.0)
    rad = np.radians(u.angle)
    for i in range(0, len(u.arc), 3):
        t = cl.tangent_at(u.arc[i])
        e = np.cos(rad)[:, None] * u.normal[i] + np.sin(rad)[:, None] * u.binormal[i]
        row_up = np.roll(e, 1, axis=0) - e  # world direction of the row above
        inside_up = np.cross(t, e)
        assert np.all(np.einsum("ij,ij->i", row_up, inside_up) > 0)


def test_polyp_appears_at_its_arc_and_angle(torso, colon_centerline, endo_dir):
    pol = torso.meta["truth"]["polyp"]
    cl = colon_centerline
    u = unfold(WallField.from_threshold(torso, -500.0), cl, angles=360)
    u.save(endo_dir / "unfolded.png")
    r = np.where(np.isfinite(u.radius), u.radius, 100.0)
    dip = np.median(r, axis=0, keepdims=True) - r  # folds span all angles: only local bumps remain
    s_p, _ = cl.project(pol["center"])
    ang = u.angle_of(s_p, pol["direction"])
    near_arc = np.abs(u.arc - s_p) <= 20
    d_ang = (u.angle - ang + 180.0) % 360.0 - 180.0
    near_ang = np.abs(d_ang) <= 45
    sub = dip[np.ix_(near_ang, near_arc)]
    jj, ii = np.unravel_index(np.argmax(sub), sub.shape)
    lab, _ = ndimage.label(sub >= 0.5 * sub.max())
    w = sub * (lab == lab[jj, ii])
    arc_c = float((w.sum(0) * u.arc[near_arc]).sum() / w.sum())
    ang_c = float((w.sum(1) * d_ang[near_ang]).sum() / w.sum())
    # the same place as an arc length along the true centerline (its own arc_length is measured there)
    colon = torso.meta["truth"]["colon"]
    arc_truth, _ = Centerline(colon.centerline, colon.radius, colon.arc_length).project(cl.at(arc_c))
    print(f"polyp in the unfolded view: bump {sub.max():.1f} mm at arc {arc_c:.1f} mm (polyp centre projects to "
          f"{s_p:.1f}); on the true centerline {arc_truth:.1f} mm vs truth {pol['arc_length']:.1f} mm; "
          f"angle off by {ang_c:.1f} degrees")
    assert sub.max() > 3.5  # the polyp stands 6 mm proud of the wall
    assert sub.max() >= np.percentile(dip, 99.9)  # one of the strongest bumps of the whole colon
    assert abs(arc_c - s_p) < 4.0 and abs(arc_truth - pol["arc_length"]) < 4.0
    assert abs(ang_c) < 10.0
    # it is bright where it faces the centerline: the picture is not black
    assert u.to_uint8().mean() > 60
