"""Ring artifacts measured on a tube, the lumen's polarity on the phantom, and curved planar
reformations of analytic tubes."""

from __future__ import annotations

import numpy as np
import pytest

from volumen.core import Volume
from volumen.endoscopy import Centerline, Endoscope, Pose, curved_reformation, estimate_lumen

R = 6.0  # tube radius, mm


def _tube(n=40, length=100) -> Volume:
    """A straight contrast-filled tube along z (1 mm voxels): 300 inside, 40 outside, a 0.6 mm logistic edge."""
    z, y, x = np.mgrid[:length, :n, :n].astype(float)
    d = np.hypot(y - (n - 1) / 2, x - (n - 1) / 2)
    return Volume((40 + 260 / (1 + np.exp((d - R) / 0.6))).astype(np.float32), spacing=(1.0, 1.0, 1.0))


def ring_energy(img) -> float:
    """RMS of the azimuthal mean of the luminance about a quartic fit in the radius (from 10 % to 45 % of the
    height), over its mean: rings are coherent around the centre, screen-fixed jitter noise averages out."""
    lum = img.rgba[..., :3].mean(axis=2)
    h, w = lum.shape
    yy, xx = np.mgrid[:h, :w]
    r = np.hypot(yy - (h - 1) / 2, xx - (w - 1) / 2).astype(int)
    prof = np.bincount(r.ravel(), lum.ravel()) / np.maximum(np.bincount(r.ravel()), 1)
    rr = np.arange(len(prof))
    sel = (rr >= 0.1 * h) & (rr <= 0.45 * h)
    fit = np.polyval(np.polyfit(rr[sel], prof[sel], 4), rr[sel])
    return float(np.sqrt(np.mean((prof[sel] - fit) ** 2)) / prof[sel].mean())


def test_composite_flythrough_has_no_rings():
    """Looking down the tube in composite mode with a sharp transfer ramp (opacity over 27 HU, the sharpest an
    estimate gives on noisy data): the default (jitter fixed per pixel) cuts the ring energy at least fivefold
    against unjittered sampling, and the jittered frame is the same in every frame (no crawling)."""
    from dataclasses import replace

    vol = _tube()
    est = replace(estimate_lumen(vol, (50, 20, 20)), spread=90.0)
    pose = Pose(position=tuple(vol.index_to_world(np.array([19.5, 19.5, 8.0]))), forward=(0, 0, 1), up=(0, 1, 0))
    endo = Endoscope(volume=vol, mode="composite", threshold=est.threshold, transfer=est.transfer())
    plain = endo.with_(jitter=False)
    a, b = endo.render(pose, (96, 96)), plain.render(pose, (96, 96))
    e_jit, e_plain = ring_energy(a), ring_energy(b)
    print(f"ring energy: {e_plain:.4f} unjittered, {e_jit:.4f} jittered (default)")
    assert endo.jitter and e_jit * 5 <= e_plain and e_jit < 0.005
    assert np.array_equal(a.rgba, endo.render(pose, (96, 96)).rgba)


def test_polarity_of_the_phantom_lumens(torso):
    """Colon: air, wall between air (-1000) and tissue; aorta: contrast, wall between tissue and contrast (300)."""
    for name, kind, lo, hi in [("colon", "air", -900, -300), ("aorta", "contrast", 60, 290)]:
        p = torso.meta["truth"][name].centerline[0]
        est = estimate_lumen(torso, np.rint(torso.world_to_index(p)[::-1]).astype(int))
        print(name, est.describe())
        assert est.kind == kind and lo < est.threshold < hi


def _arc_tube(rc=30.0, n=80):
    """A tube of radius R bent along a quarter circle of radius rc in the plane z = 0 (1 mm voxels), and its
    centerline."""
    z, y, x = np.mgrid[-12:13, -6:n, -6:n].astype(float)
    d = np.hypot(np.hypot(x, y) - rc, z)
    ang = np.arctan2(y, x)
    d = np.where((ang >= 0) & (ang <= np.pi / 2), d, np.hypot(d, 0) + 100 * np.minimum(np.abs(ang), 1))
    data = (40 + 260 / (1 + np.exp((d - R) / 0.6))).astype(np.float32)
    aff = np.eye(4)
    aff[:3, 3] = (-6, -6, -12)
    vol = Volume(data, spacing=(1.0, 1.0, 1.0), affine=aff)
    t = np.linspace(0, np.pi / 2, 400)
    pts = np.stack([rc * np.cos(t), rc * np.sin(t), 0 * t], axis=1)
    arc = rc * t
    return vol, Centerline(pts, np.full(len(t), R), arc), rc


def test_straightened_cpr_shows_the_tube_straight_and_true_to_length():
    """Straightened: rows cover the arc length (pi rc / 2), the tube is a band centred on the middle column, its
    width (values above half-way) 2 R within one pixel in every row away from the ends."""
    vol, cl, rc = _arc_tube()
    cpr = curved_reformation(vol, cl, kind="straightened", width=30.0, pixel=0.5)
    assert cpr.arc[-1] == pytest.approx(np.pi * rc / 2, abs=0.5)
    rows = cpr.values[20:-20]
    width = (rows > 170).sum(axis=1) * cpr.pixel
    centre = ((rows > 170) * np.arange(rows.shape[1])).sum(axis=1) / (rows > 170).sum(axis=1)
    off = np.abs(centre - cpr.centre[0])
    print(f"band width {width.min():.2f}..{width.max():.2f} mm, centre offset {off.max():.2f} px")
    assert np.all(np.abs(width - 2 * R) <= 1.0) and np.all(off <= 1.0)


def test_stretched_cpr_keeps_the_course():
    """Stretched along v = x: rows span the curve's extent across v (rc), and in each row where the tube crosses
    the sampled lines steeply (tangent within 60 degrees of the rows' normal: the first rc / 2 mm) it sits at the
    centerline's column (its x) within one pixel. Where the path runs along v the tube smears along the row, as
    in every stretched CPR."""
    vol, cl, rc = _arc_tube()
    cpr = curved_reformation(vol, cl, kind="stretched", width=30.0, pixel=0.5, direction=(1, 0, 0))
    assert (len(cpr.arc) - 1) * cpr.pixel == pytest.approx(rc, abs=0.5)
    steep = slice(2, int(0.5 * rc / cpr.pixel))
    rows = cpr.values[steep]
    peak = ((rows > 170) * np.arange(rows.shape[1])).sum(axis=1) / np.maximum((rows > 170).sum(axis=1), 1)
    err = np.abs(peak - cpr.centre[steep])
    print(f"tube centre vs centerline column: max {err.max():.2f} px; columns span {cpr.centre.min():.0f}.."
          f"{cpr.centre.max():.0f}")
    assert err.max() <= 1.0 and np.ptp(cpr.centre) * cpr.pixel == pytest.approx(rc, abs=1.0)
