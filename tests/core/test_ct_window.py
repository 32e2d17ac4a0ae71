"""A CT read without a modality (NIfTI, NRRD) is still shown with CT windows: told apart by its values."""

from __future__ import annotations

import nibabel as nib
import numpy as np
import pytest

import volumen
from volumen.core import WINDOW_PRESETS, Volume, default_window, is_ct, slice_image
from volumen.core._slices import SLICE_PERCENTILES
from volumen.core._subject import subject_values
from volumen.data import phantom, sample, samples


@pytest.fixture(scope="module")
def torso():
    return phantom("torso", size=(40, 48, 48))


def _bare(vol, data=None, **kw):
    return Volume(vol.data if data is None else data, affine=vol.affine, modality=kw.get("modality", "OT"),
                  units=kw.get("units", ""))


def test_a_ct_without_modality_from_nifti_gets_the_soft_tissue_window(torso, tmp_path):
    """Written by nibabel alone (no modality anywhere in the file), read back: CT values, CT window."""
    path = tmp_path / "ct.nii.gz"
    nib.save(nib.Nifti1Image(np.ascontiguousarray(torso.data.transpose(2, 1, 0)), torso.affine), path)
    vol = volumen.load(path)
    assert vol.modality != "CT" and vol.units != "HU"
    assert is_ct(vol)
    assert default_window(vol) == WINDOW_PRESETS["soft-tissue"]
    assert np.array_equal(slice_image(vol, "axial"), slice_image(vol, "axial", window="soft-tissue"))


@pytest.mark.parametrize("case", ["scanner units (air at 0)", "float PET-like", "no bone", "known MR"])
def test_other_volumes_are_not_taken_for_ct(torso, case):
    d = torso.data.astype(np.float64)
    vol = {"scanner units (air at 0)": lambda: _bare(torso, (d + 1024).astype(np.int16)),
           "float PET-like": lambda: _bare(torso, (d * 0.37 + 0.5).astype(np.float32)),
           "no bone": lambda: _bare(torso, np.minimum(d, 250).astype(np.int16)),
           "known MR": lambda: _bare(torso, modality="MR")}[case]()
    assert not is_ct(vol)
    lo, hi = vol.value_range()  # no far outliers: the display range
    bottom, top = np.percentile(subject_values(vol), SLICE_PERCENTILES)  # the subject's, above the background
    assert lo < bottom < top <= hi and default_window(vol).range == pytest.approx((bottom, top))


def test_padding_outside_the_field_of_view_does_not_hide_a_ct(torso):
    """Scanners pad the corners outside their circular field of view with -3024 (or -2048)."""
    d = torso.data.astype(np.int16).copy()
    nz, ny, nx = d.shape
    y, x = np.mgrid[:ny, :nx]
    d[:, (y - ny / 2) ** 2 + (x - nx / 2) ** 2 > (0.5 * nx) ** 2] = -3024  # the corners, a fifth of each slice
    assert is_ct(_bare(torso, d))


def test_the_mri_template_is_not_a_ct():
    if "ch2better" not in samples():
        pytest.skip("MRIcron templates not installed (Debian package mricron-data)")
    assert not is_ct(sample("ch2better"))


def test_the_app_state_opens_a_bare_ct_in_the_soft_tissue_window(torso):
    from volumen.app._state import AppState

    st = AppState()
    st.set_volume(_bare(torso), "bare")
    assert st.window == WINDOW_PRESETS["soft-tissue"]
