"""Region growing on the torso phantom's colon: the lumen, and no leak into the lungs."""

from __future__ import annotations

import numpy as np
import pytest

from volumen.segment import region_grow


@pytest.fixture(scope="module")
def torso():
    try:
        from volumen.data import phantom
    except ImportError as exc:  # the phantom is written concurrently; skip until it lands
        pytest.skip(f"volumen.data is not importable yet: {exc}")
    return phantom("torso", noise=0, blur=0)


def test_colon_from_one_seed_recovers_the_lumen_without_leaking(torso):
    colon = torso.meta["truth"]["colon"]
    seed = colon.centerline[0]  # world mm, the rectum end
    grown = region_grow(torso, seed, lo=-1100, hi=-400, connectivity=6).data.astype(bool)
    truth = colon.mask
    dice = 2 * (grown & truth).sum() / (grown.sum() + truth.sum())
    assert dice >= 0.95, f"Dice {dice:.4f}"
    # the lungs: large connected regions of lung parenchyma (-850 HU in the noise-free phantom;
    # isolated partial-volume voxels at the colon wall can take that value too)
    from scipy import ndimage

    labels, _ = ndimage.label((torso.data >= -860) & (torso.data <= -840))
    sizes = np.bincount(labels.ravel())
    sizes[0] = 0
    lungs = np.isin(labels, np.flatnonzero(sizes > 1000))
    assert lungs.sum() > 10000
    assert not (grown & lungs).any(), "region growing leaked into the lungs"
    # and nothing outside the lumen's one-voxel neighbourhood
    assert not (grown & ~ndimage.binary_dilation(truth, np.ones((3, 3, 3), bool))).any()
