"""The phantoms of anatomy the lumen estimate was not tuned on: deterministic, their ground truth agrees
with their data, and each has the feature of its failure class where it should be."""

from __future__ import annotations

import hashlib

import numpy as np
import pytest
from scipy import ndimage

from volumen.data import phantom

NAMES = ("arch", "airways", "tagged_colon", "washout")


@pytest.fixture(scope="module")
def made():
    return {name: phantom(name) for name in NAMES}


@pytest.mark.parametrize("name", NAMES)
def test_deterministic_and_landmarks_in_the_lumen(name, made):
    def sha(**params):
        return hashlib.sha256(phantom(name, size=40, **params).data.tobytes()).hexdigest()

    assert sha() == sha() != sha(seed=1)
    vol = made[name]
    tube = next(t for t in vol.meta["truth"].values() if hasattr(t, "mask"))
    for point in (vol.meta["truth"]["landmarks"][k] for k in ("start", "end")):
        k, j, i = np.rint(vol.world_to_index(point)[::-1]).astype(int)
        assert tube.mask[k, j, i], (name, point)


@pytest.mark.parametrize("name, lumen, wall", [("arch", 330, 45), ("airways", -1000, 40), ("washout", 320, 60)])
def test_truth_masks_are_the_voxels_on_the_lumens_side_of_half_way(name, lumen, wall, made):
    """Away from the edge (two voxels in, two out) the data is the lumen's and the wall's side of half-way for
    >= 99 % of the voxels (noise and uneven contrast included)."""
    vol = made[name]
    mask = next(t for t in vol.meta["truth"].values() if hasattr(t, "mask")).mask
    half, sign = 0.5 * (lumen + wall), np.sign(lumen - wall)
    inner = ndimage.binary_erosion(mask, iterations=2)
    assert np.mean(sign * (vol.data[inner] - half) > 0) >= 0.99


def test_the_arch_passes_within_its_gap_of_the_lung(made):
    """The lung (below -600 HU, outside the airways) comes within 4 mm (+- one 1.5 mm voxel) of the aorta's lumen."""
    vol = made["arch"]
    aorta = vol.meta["truth"]["aorta"].mask
    dist = ndimage.distance_transform_edt(~aorta, sampling=vol.spacing)
    lung = ndimage.binary_erosion(vol.data < -600, iterations=1) & (dist < 30)
    closest = float(dist[lung].min())
    print(f"lung {closest:.1f} mm from the aortic lumen")
    assert 2.5 <= closest <= 5.5


def test_the_bronchial_walls_are_one_or_two_voxels(made):
    """Two voxels and a half outside the segmental bronchi's lumen the data is lung again (below -700 HU) for most
    voxels: walls one voxel thick, as the trachea's is two."""
    vol = made["airways"]
    tube = vol.meta["truth"]["airway"]
    mask = tube.mask
    dist = ndimage.distance_transform_edt(~mask, sampling=vol.spacing)
    seg = np.zeros(vol.shape, bool)
    for b in tube.branches:
        if b.name[:2] in ("rs", "ls"):
            k, j, i = np.rint(vol.world_to_index(b.centerline)[:, ::-1]).astype(int).T
            seg[k, j, i] = True
    near = ndimage.binary_dilation(seg, iterations=6) & (dist > 2.0) & (dist <= 3.0)
    frac = float(np.mean(vol.data[near] < -700))
    print(f"lung at 2-3 mm outside the segmental bronchi: {frac:.2f}")
    assert frac >= 0.5


def test_the_fluid_lies_flat_under_its_level(made):
    """The tagged fluid is the lumen under the horizontal level, bright (median over 500 HU), and at least a fifth
    of the lumen."""
    vol = made["tagged_colon"]
    tr = vol.meta["truth"]
    fluid, lumen, level = tr["fluid"], tr["colon"].mask, tr["level"]
    y = vol.index_to_world(np.argwhere(fluid)[:, ::-1].astype(float))[:, 1]
    assert fluid.sum() > 0.2 * lumen.sum() and np.all(fluid <= lumen) and y.max() < level
    assert np.median(vol.data[ndimage.binary_erosion(fluid, iterations=2)]) > 500
