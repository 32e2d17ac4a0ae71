"""The whole-region CTs built for speed measurements (``phantom("abdomen")``, ``phantom("chest")``): tissue
where the anatomy puts it, the scanner's noise, and soft tissue in most rays through the body."""

from __future__ import annotations

import numpy as np
import pytest

from volumen.data import phantom

SIZE = (75, 68, 82)  # (nz, ny, nx): 4.9 mm voxels, a third of the benchmark's smaller size


@pytest.fixture(scope="module", params=["abdomen", "chest"])
def scan(request):
    return request.param, phantom(request.param, size=SIZE)


def _hu(vol, xyz, r=1):
    """Median HU of the (2r+1)^3 voxels around the world point ``xyz`` (mm)."""
    i, j, k = np.rint(vol.world_to_index(xyz)).astype(int)
    return float(np.median(vol.data[k - r:k + r + 1, j - r:j + r + 1, i - r:i + r + 1]))


def test_field_of_view_and_determinism(scan):
    name, vol = scan
    assert vol.shape == SIZE and vol.dtype == np.int16
    np.testing.assert_allclose(np.array(vol.shape[::-1]) * vol.spacing[::-1], (400.0, 331.0, 367.0))
    again = phantom(name, size=SIZE)
    assert np.array_equal(vol.data, again.data)
    small = (30, 28, 33)
    assert not np.array_equal(phantom(name, size=small).data, phantom(name, size=small, seed=1).data)


def test_tissue_values(scan):
    """Organ, fat, air and bone values (HU) at known places, within the texture and noise."""
    name, vol = scan
    if name == "abdomen":
        lm = vol.meta["truth"]["landmarks"]
        assert 80 < _hu(vol, lm["liver"]) < 130 and 90 < _hu(vol, lm["spleen"]) < 140
        assert _hu(vol, (0.0, -65.0, -20.0)) > 150  # a vertebral body
        assert -130 < _hu(vol, (0.0, 95.0, -100.0)) < -70  # subcutaneous fat in front
    else:
        assert _hu(vol, (90.0, -10.0, 60.0)) < -750 and _hu(vol, (-90.0, -10.0, 60.0)) < -750  # both lungs
        assert _hu(vol, (-5.0, 25.0, -10.0)) > 120  # contrast in the heart
    assert _hu(vol, (0.0, 150.0, 0.0), 0) < -950  # air in front of the body


def test_noise_is_about_12_hu(scan):
    name, noisy = scan
    clean = phantom(name, size=SIZE, noise=0)
    diff = noisy.data.astype(float) - clean.data
    inside = (clean.data > -900) & (noisy.data > -1020)  # no clipping at -1024
    assert 10.5 < diff[inside].std() < 13.5 and abs(diff[inside].mean()) < 0.5


def test_soft_tissue_in_most_rays(scan):
    """Seen from the front (rays along y), most lines of sight through the body cross centimetres of soft tissue
    (-200..200 HU), as in a real whole-region CT."""
    name, vol = scan
    soft = (vol.data >= -200) & (vol.data <= 200)
    body = (vol.data > -500).any(axis=1)  # (z, x) lines of sight that meet the body
    mm = soft.sum(axis=1) * vol.spacing[1]
    share = float(np.mean(mm[body] >= 20.0))
    print(f"{name}: {100 * body.mean():.0f}% of the lines of sight meet the body, {100 * share:.0f}% of those cross "
          f">= 2 cm of soft tissue")
    assert body.mean() > 0.6 and share > 0.8
