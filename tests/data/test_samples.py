"""Installed sample data: found by scanning, loaded through volumen.io, checked against nibabel."""

from __future__ import annotations

from pathlib import Path

import nibabel as nib
import numpy as np
import pytest

import volumen
from volumen.data import _samples, sample, samples
from volumen.errors import SampleDataMissingError, VolumeReadError

MRICRON = Path("/usr/share/mricron/templates")


def _assert_same_as_nibabel(vol, path, n_points=500):
    """Same voxels at the same world positions as nibabel reads them (whatever the axis order)."""
    img = nib.load(str(path))
    ref = np.asarray(img.dataobj)
    assert vol.data.size == ref.size and sorted(vol.shape) == sorted(ref.shape)
    rng = np.random.default_rng(0)
    ijk = np.stack([rng.integers(0, n, n_points) for n in ref.shape], axis=1)
    world = nib.affines.apply_affine(img.affine, ijk)
    ours = np.rint(vol.world_to_index(world)).astype(int)  # (i, j, k) of our volume
    np.testing.assert_allclose(vol.world_to_index(world), ours, atol=1e-4)  # lands on voxel centres
    np.testing.assert_array_equal(vol.data[ours[:, 2], ours[:, 1], ours[:, 0]], ref[tuple(ijk.T)])
    lo, hi = vol.bounds()
    corner_ijk = np.array(np.meshgrid(*[[0, n - 1] for n in ref.shape])).reshape(3, -1).T
    corners = nib.affines.apply_affine(img.affine, corner_ijk)
    np.testing.assert_allclose(lo, corners.min(axis=0), atol=1e-4)
    np.testing.assert_allclose(hi, corners.max(axis=0), atol=1e-4)


@pytest.fixture
def fake_templates(tmp_path, monkeypatch):
    """A search folder with one small LAS NIfTI file (and files that are not volumes)."""
    data = np.arange(5 * 6 * 7, dtype=np.int16).reshape(5, 6, 7)
    affine = np.array([[-2.0, 0, 0, 40.0], [0, 1.5, 0, -10.0], [0, 0, 3.0, 5.0], [0, 0, 0, 1]])
    nib.save(nib.Nifti1Image(data, affine), tmp_path / "tiny.nii.gz")
    (tmp_path / "tiny.nii.txt").write_text("labels")
    (tmp_path / "tiny.nii.lut").write_bytes(b"\0" * 768)
    monkeypatch.setattr(_samples, "SEARCH_DIRS", (tmp_path,))
    return tmp_path


def test_samples_scans_the_search_folders(fake_templates):
    assert samples() == {"tiny": fake_templates / "tiny.nii.gz"}
    vol = sample("tiny")
    assert vol.name == "tiny" and vol.meta["sample"] == "tiny"
    _assert_same_as_nibabel(vol, fake_templates / "tiny.nii.gz")


def test_missing_sample_raises_with_install_hint(tmp_path, monkeypatch):
    monkeypatch.setattr(_samples, "SEARCH_DIRS", (tmp_path / "absent",))
    assert samples() == {}
    with pytest.raises(SampleDataMissingError, match=r"sudo apt-get install mricron-data") as info:
        sample("mni-brain")
    assert isinstance(info.value, VolumeReadError)
    assert "'mni-brain'" in str(info.value) and "ch2better" in str(info.value)


def test_unknown_sample_lists_what_is_installed(fake_templates):
    with pytest.raises(SampleDataMissingError, match="installed: tiny"):
        sample("ch2better")


@pytest.fixture
def mricron():
    if not MRICRON.is_dir():
        pytest.skip(f"MRIcron templates not installed ({MRICRON} is absent); "
                    "on Debian: sudo apt-get install mricron-data")
    return MRICRON


def test_installed_templates_are_listed(mricron):
    found = samples()
    assert found["mni-brain"] == found["ch2better"] == mricron / "ch2better.nii.gz"
    on_disk = {p.name.removesuffix(".gz").removesuffix(".nii") for p in mricron.glob("*.nii*")
               if p.name.endswith((".nii", ".nii.gz"))}
    assert set(found) == on_disk | {"mni-brain"}


def test_mni_brain_loads_like_nibabel(mricron):
    vol = sample("mni-brain")
    assert vol.name == "mni-brain"
    assert vol.orientation == "RAS" and vol.spacing == (0.5, 0.5, 0.5)
    _assert_same_as_nibabel(vol, mricron / "ch2better.nii.gz")


def test_left_handed_template_keeps_left_and_right(mricron):
    las = next((p for p in sorted(mricron.glob("*.nii.gz")) if nib.aff2axcodes(nib.load(str(p)).affine)[0] == "L"),
               None)
    if las is None:
        pytest.skip("no LAS template installed")
    _assert_same_as_nibabel(sample(las.name.removesuffix(".nii.gz")), las)


def test_an_mricron_atlas_is_read_with_the_names_beside_it(mricron):
    """``aal.nii.gz`` with ``aal.nii.txt`` (116 regions of the AAL atlas, ``1 Precentral_L 2001``)."""
    labels = volumen.load_labels(mricron / "aal.nii.gz")
    assert len(labels.names) == 116 and labels.names[1] == "Precentral_L" and labels.names[116] == "Vermis_10"
