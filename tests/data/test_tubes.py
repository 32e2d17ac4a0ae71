"""Ground truth of tubular structures: centerlines inside and centred in their lumens, masks equal to the data."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

from volumen.data import Tube, phantom

# (phantom fixture, truth key, lumen HU)
TUBES = [("torso", "colon", -1000), ("torso", "airway", -1000), ("torso", "aorta", 300),
         ("head", "nasal_airway", -1000)]


def _all_tubes(tube: Tube):
    yield tube
    for b in tube.branches:
        yield from _all_tubes(b)


def _voxels(vol, points):
    """(N, 3) world mm -> (N, 3) nearest (k, j, i) indices."""
    return np.rint(vol.world_to_index(points)).astype(int)[:, ::-1]


@pytest.mark.parametrize("which, key, hu", TUBES)
def test_centerline_inside_and_centred_in_lumen(request, which, key, hu):
    vol = request.getfixturevalue(which)
    tube = vol.meta["truth"][key]
    assert tube.mask.shape == vol.shape and tube.mask.dtype == bool
    edt = ndimage.distance_transform_edt(tube.mask, sampling=vol.spacing)  # mm to the nearest non-lumen voxel
    for t in _all_tubes(tube):
        assert t.mask is tube.mask  # branches share the tree's mask
        assert t.centerline.shape == (len(t.radius), 3) and len(t.radius) > 20
        step = np.linalg.norm(np.diff(t.centerline, axis=0), axis=1)
        assert 0.5 < step.min() and step.max() < 1.5  # about one point per mm
        k, j, i = _voxels(vol, t.centerline).T
        assert np.all(t.mask[k, j, i]), f"{t.name}: centerline leaves the lumen"
        ratio = edt[k, j, i] / t.radius
        assert ratio.min() >= 0.4, f"{t.name}: centerline {ratio.min():.2f} radius from the wall"
        # roughly centred: the lumen reaches about one radius around the centerline on average
        assert 0.7 < np.median(edt[k, j, i] / t.radius) < 1.6, t.name


# the HU around each phantom's lumens (torso: the tubes' walls; head: the soft tissue of the face)
WALL_HU = {"torso": 40, "head": 45}


def _sides(data, hu, wall=40):
    """(strictly on the lumen's side, on it or exactly half-way) of the threshold half-way between the
    lumen's value ``hu`` and the wall's: partial-volume edges put a voxel whose centre is inside the
    lumen on the lumen's side, one whose centre is outside on the wall's (a value rounded to exactly
    half-way, a centre within ~0.001 mm of the surface, may be either)."""
    half = (hu + wall) / 2.0
    return (data < half, data <= half) if hu < wall else (data > half, data >= half)


@pytest.mark.parametrize("which, key, hu", TUBES)
def test_mask_is_exactly_the_lumen_in_the_data(request, which, key, hu):
    vol = request.getfixturevalue(which)
    tube = vol.meta["truth"][key]
    strict, loose = _sides(vol.data, hu, WALL_HU[which])
    assert np.all(loose[tube.mask])  # every lumen voxel is on the lumen's side of the half-way threshold
    interior = ndimage.binary_erosion(tube.mask, iterations=2)
    assert np.mean(vol.data[interior] == hu) > 0.95  # and away from the wall it is exactly the lumen's value
    strict_labels, _ = ndimage.label(strict)
    loose_labels, _ = ndimage.label(loose)
    if which == "head":  # the nasal airway opens into the air in front of the nose (a corner voxel's)
        assert np.all(loose_labels[tube.mask] == loose_labels[0, 0, 0])
        return
    # the lumen is the 6-connected component of lumen-side voxels that holds the centerline
    k, j, i = _voxels(vol, tube.centerline[len(tube.centerline) // 2:][:1]).T
    inner = strict_labels == strict_labels[k[0], j[0], i[0]]
    outer = loose_labels == loose_labels[k[0], j[0], i[0]]
    assert np.all(tube.mask <= outer) and np.all(inner <= tube.mask | (loose & ~strict))
    assert inner.sum() > 0.99 * tube.mask.sum()  # all but the values rounded to exactly half-way


def test_mask_values_with_default_noise_and_blur_stay_in_their_class():
    """With the default scanner blur (0.5 voxel) and noise (10 HU), lumen voxels two voxels from the
    wall keep their class value within noise (but for the sub-voxel crests of the folds nearby), and
    without noise lumen voxels stay on the lumen side of the half-way threshold between lumen and
    wall (so a threshold there recovers the lumen) but for a handful where blurred edges meet."""
    vol = phantom("torso")
    truth = vol.meta["truth"]
    deep_colon = ndimage.binary_erosion(truth["colon"].mask, iterations=2)
    deep_aorta = ndimage.binary_erosion(truth["aorta"].mask, iterations=2)
    colon, aorta = vol.data[deep_colon].astype(float), vol.data[deep_aorta].astype(float)
    assert abs(colon.mean() + 1000) < 2 and np.percentile(colon, 99) < -970
    assert abs(aorta.mean() - 300) < 2 and np.percentile(aorta, 1) > 270
    assert 8 < np.median(np.abs(colon + 1000)) / 0.6745 < 12  # the noise's sigma, robustly
    clean = phantom("torso", noise=0)
    for key, hu in (("colon", -1000), ("aorta", 300), ("airway", -1000)):
        mask = clean.meta["truth"][key].mask
        strict, loose = _sides(clean.data, hu)
        ring = ndimage.binary_dilation(mask) & ~mask
        assert np.mean(loose[mask]) > 0.999 and np.mean(strict[ring]) < 0.001, key


def test_haustral_folds_narrow_but_never_close_the_colon():
    folded = phantom("torso", noise=0, blur=0).meta["truth"]["colon"]
    smooth = phantom("torso", noise=0, blur=0, fold_depth=0.0).meta["truth"]["colon"]
    np.testing.assert_allclose(folded.centerline, smooth.centerline)
    ratio = folded.radius / smooth.radius
    assert ratio.min() == pytest.approx(0.6, abs=0.01)  # the deepest folds leave 60 % of the radius open
    assert ratio.max() == pytest.approx(1.0)
    # periodic: the narrowings recur every ~24 mm along the colon
    s = folded.arc_length
    minima = s[1:-1][(ratio[1:-1] < ratio[:-2]) & (ratio[1:-1] <= ratio[2:]) & (ratio[1:-1] < 0.7)]
    assert len(minima) >= 15
    np.testing.assert_allclose(np.diff(minima), 24.0, atol=1.01)
    assert folded.mask.sum() < 0.92 * smooth.mask.sum()  # the folds take lumen away
    with pytest.raises(ValueError, match="fold_depth"):
        phantom("torso", fold_depth=0.7)


def test_polyp(torso):
    truth = torso.meta["truth"]
    colon, polyp = truth["colon"], truth["polyp"]
    pm = polyp["mask"]
    h = max(torso.spacing)
    r = polyp["radius"]
    assert 4.0 <= r <= 6.0
    assert pm.sum() >= 0.4 * (2 / 3 * np.pi * r**3) / np.prod(torso.spacing)  # about a hemisphere of voxels
    half = (-1000 + 40) / 2.0  # between air and soft tissue
    assert np.all(torso.data[pm] >= half)  # soft tissue (on its side of the partial-volume edge)
    assert np.mean(torso.data[pm] == 40) > 0.3  # its core exactly
    assert not np.any(pm & colon.mask)  # not lumen
    ring = ndimage.binary_dilation(pm) & ~pm
    assert np.any(ring & colon.mask)  # protrudes into the lumen (air around it) ...
    assert np.any(ring & ~colon.mask & (torso.data == 40))  # ... from the wall it touches
    # all its voxels lie in the sphere, on the lumen side of the wall
    idx = np.argwhere(pm)[:, ::-1]
    world = torso.index_to_world(idx)
    assert np.linalg.norm(world - polyp["center"], axis=1).max() <= r + 1e-6
    # arc length: the centerline point at that arc length faces the polyp across the lumen
    s = colon.arc_length
    c = np.array([np.interp(polyp["arc_length"], s, colon.centerline[:, a]) for a in range(3)])
    tangent = np.array([np.interp(polyp["arc_length"], s, np.gradient(colon.centerline[:, a], s)) for a in range(3)])
    to_center = np.asarray(polyp["center"]) - c
    assert np.linalg.norm(to_center) == pytest.approx(polyp["lumen_radius"], abs=0.05)
    assert abs(np.dot(to_center / np.linalg.norm(to_center), tangent / np.linalg.norm(tangent))) < 0.05
    assert np.linalg.norm(np.asarray(polyp["tip"]) - c) == pytest.approx(polyp["lumen_radius"] - r, abs=0.05)
    assert np.linalg.norm(world - c, axis=1).min() == pytest.approx(polyp["lumen_radius"] - r, abs=h)
    assert np.interp(polyp["arc_length"], s, colon.radius) == pytest.approx(polyp["lumen_radius"], rel=0.01)
    assert truth["landmarks"]["polyp"] == polyp["center"]
