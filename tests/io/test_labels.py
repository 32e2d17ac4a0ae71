"""Segmentations as label maps: names tables, mask folders, .seg.nrrd layers, DICOM SEG (highdicom), grids.

Every round trip compares labels and geometry with what was written (exact: labels are integers,
affines to 1e-6 mm). About 5 s.
"""

from __future__ import annotations

import json

import nibabel as nib
import numpy as np
import pytest

import volumen
from volumen.core import LabelMap, Volume
from volumen.data import organ_phantom
from volumen.errors import LabelError
from volumen.io import labels_on_grid, load_labels, read_names_table


@pytest.fixture(scope="module")
def organs():
    return organ_phantom(32)


def _nifti(path, data, affine):
    nib.save(nib.Nifti1Image(np.asarray(data).transpose(2, 1, 0), affine), str(path))


def test_label_map_with_json_names_beside_it(tmp_path, organs):
    vol, truth = organs
    _nifti(tmp_path / "seg.nii.gz", truth.data, truth.affine)
    (tmp_path / "seg.json").write_text(json.dumps({str(v): n for v, n in truth.names.items()} | {"9": "absent"}))
    got = volumen.load_labels(tmp_path / "seg.nii.gz")
    assert got.names == truth.names
    np.testing.assert_array_equal(got.data, truth.data)
    np.testing.assert_allclose(got.affine, truth.affine, atol=1e-6)
    ml = got.volumes_ml()
    assert ml[1] == pytest.approx(truth.counts()[1] * 8 / 1000)


def test_mricron_names_table_beside_an_atlas_is_read(tmp_path, organs):
    """MRIcron names an atlas's table after the image less ``.gz`` (``aal.nii.txt``): ``value name [group]``,
    space or tab separated, with a row for 0."""
    vol, truth = organs
    _nifti(tmp_path / "atlas.nii.gz", truth.data, truth.affine)
    rows = [f"{v}\t{n}\t{2000 + v}" for v, n in truth.names.items()]
    (tmp_path / "atlas.nii.txt").write_text("0\tUnclassified\n" + "\n".join(rows) + "\n")
    got = volumen.load_labels(tmp_path / "atlas.nii.gz")
    assert got.names == truth.names and got.meta["names_table"].endswith("atlas.nii.txt")


@pytest.mark.parametrize("text,suffix", [
    ("# ITK-SnAP Label Description File\n    0     0    0    0        0  0  0    \"Clear Label\"\n"
     "    1   255    0    0        1  1  1    \"liver\"\n    2     0  255    0        1  1  1    \"spleen\"\n", ".txt"),
    ("# Slicer colour table\n0 background 0 0 0 0\n1 liver 255 0 0 255\n2 spleen 0 255 0 255\n", ".ctbl"),
    ("value,name,r,g,b\n1,liver,255,0,0\n2,spleen,0,255,0\n", ".csv"),
    ('[{"value": 1, "name": "liver", "color": [1, 0, 0]}, {"value": 2, "name": "spleen", "color": [0, 1, 0]}]',
     ".json"),
])
def test_names_tables(tmp_path, text, suffix):
    f = tmp_path / f"t{suffix}"
    f.write_text(text)
    t = read_names_table(f)
    assert {v: n for v, (n, _) in t.items()} == {1: "liver", 2: "spleen"}
    assert t[1][1] == pytest.approx((1.0, 0.0, 0.0)) and t[2][1] == pytest.approx((0.0, 1.0, 0.0))


def test_names_table_that_does_not_match(tmp_path, organs):
    _, truth = organs
    _nifti(tmp_path / "seg.nii.gz", truth.data, truth.affine)
    (tmp_path / "names.json").write_text(json.dumps({"1": "liver", "2": "spleen"}))
    with pytest.raises(LabelError) as e:
        load_labels(tmp_path / "seg.nii.gz", names=tmp_path / "names.json")
    assert "names.json" in str(e.value) and "3, 4, 5" in str(e.value) and "\n" not in str(e.value)


def test_totalsegmentator_folder(tmp_path, organs):
    _, truth = organs
    for v, n in truth.names.items():
        _nifti(tmp_path / f"{n}.nii.gz", (truth.data == v).astype(np.uint8), truth.affine)
    got = load_labels(tmp_path)
    assert sorted(got.names.values()) == sorted(truth.names.values())
    for v, n in truth.names.items():
        np.testing.assert_array_equal(got.mask(n), truth.data == v)


def test_seg_nrrd_two_layers(tmp_path):
    import nrrd

    a = np.zeros((10, 12, 14), np.uint8)
    b = np.zeros_like(a)
    a[2:6, 3:9, 4:10] = 1   # layer 0: "tumour" value 1
    b[4:8, 5:11, 2:7] = 3   # layer 1: "vessel" value 3, overlapping the tumour
    # NRRD order: list axis first, then i (x), j (y), k (z); LPS
    data = np.stack([a, b]).transpose(0, 3, 2, 1)
    header = {"type": "uint8", "dimension": 4, "space": "left-posterior-superior",
              "kinds": ["list", "domain", "domain", "domain"],
              "space directions": np.array([[np.nan] * 3, [0.7, 0, 0], [0, 0.8, 0], [0, 0, 1.5]]),
              "space origin": np.array([10.0, 20.0, -30.0]),
              "Segment0_Name": "tumour", "Segment0_Color": "1 0.5 0", "Segment0_LabelValue": "1", "Segment0_Layer": "0",
              "Segment1_Name": "vessel", "Segment1_Color": "0 0 1", "Segment1_LabelValue": "3", "Segment1_Layer": "1"}
    f = tmp_path / "s.seg.nrrd"
    nrrd.write(str(f), data, header)
    got = load_labels(f)
    assert got.names == {1: "tumour", 2: "vessel"} and got.meta["layers"] == 2
    assert got.colors[1] == pytest.approx((1.0, 0.5, 0.0))
    np.testing.assert_array_equal(got.mask("vessel"), b == 3)
    np.testing.assert_array_equal(got.mask("tumour"), (a == 1) & (b != 3))
    expect = np.diag([-0.7, -0.8, 1.5, 1.0])
    expect[:3, 3] = (-10.0, -20.0, -30.0)
    np.testing.assert_allclose(got.affine, expect, atol=1e-9)
    assert any("overlap" in w for w in got.meta["warnings"])


def test_resampled_onto_a_flipped_cropped_scan_and_no_overlap(organs):
    vol, truth = organs
    flip = np.diag([-1.0, 1.0, 1.0, 1.0])
    flip[0, 3] = truth.shape[2] - 1
    scan = Volume(vol.data[4:, :, ::-1], vol.spacing, vol.affine @ flip @ _shift(0, 0, 4))
    got = labels_on_grid(truth, scan)
    np.testing.assert_array_equal(got.data, truth.data[4:, :, ::-1])
    far = Volume(vol.data, vol.spacing, _shift(1000.0, 0, 0) @ vol.affine)
    with pytest.raises(LabelError, match="does not overlap the scan"):
        labels_on_grid(truth, far)


def _shift(x, y, z):
    m = np.eye(4)
    m[:3, 3] = (x, y, z)
    return m


def test_not_a_label_map(tmp_path):
    _nifti(tmp_path / "f.nii.gz", np.full((4, 4, 4), 0.5, np.float32), np.eye(4))
    with pytest.raises(LabelError, match="whole numbers"):
        load_labels(tmp_path / "f.nii.gz")


def test_label_map_dataclass_defaults():
    lm = LabelMap(np.array([[[0, 2], [7, 0]]]))
    assert lm.names == {2: "label_2", 7: "label_7"} and set(lm.colors) == {2, 7}
    with pytest.raises(KeyError, match="label_2"):
        lm.value_of("liver")


def _seg_from_series(files, mask, fractional, tmp_path, name="seg.dcm"):
    """A DICOM SEG written with highdicom over ``files`` (the source slices, in ``mask``'s slice order)."""
    import highdicom as hd
    import pydicom
    from pydicom.sr.codedict import codes

    sources = [pydicom.dcmread(str(f)) for f in files]
    for ds in sources:  # the patient / study module highdicom copies (empty: the factory writes no identity)
        for kw in ("PatientName", "PatientID", "PatientBirthDate", "PatientSex", "StudyDate", "StudyTime",
                   "StudyID", "AccessionNumber", "ReferringPhysicianName"):
            if kw not in ds:
                setattr(ds, kw, "")
    desc = [hd.seg.SegmentDescription(
        segment_number=i + 1, segment_label=label, segmented_property_category=codes.SCT.Organ,
        segmented_property_type=codes.SCT.Organ, algorithm_type=hd.seg.SegmentAlgorithmTypeValues.MANUAL)
        for i, label in enumerate(["liver", "kidney"])]
    pixels = np.stack([m.astype(np.float32 if fractional else np.uint8) for m in mask], axis=-1)
    seg = hd.seg.Segmentation(
        source_images=sources, pixel_array=pixels,
        segmentation_type=hd.seg.SegmentationTypeValues.FRACTIONAL if fractional
        else hd.seg.SegmentationTypeValues.BINARY,
        segment_descriptions=desc, series_instance_uid=hd.UID(), series_number=2, sop_instance_uid=hd.UID(),
        instance_number=1, manufacturer="volumen tests", manufacturer_model_name="test",
        software_versions="0", device_serial_number="0", omit_empty_frames=False)
    seg.save_as(str(tmp_path / name))
    return tmp_path / name


@pytest.mark.parametrize("fractional", [False, True])
def test_dicom_seg_round_trip(tmp_path, fractional):
    from tests.io.dicom_factory import oblique_cosines, stack_positions, write_series

    n = 12
    row, col = oblique_cosines()
    pos = stack_positions((-20.0, 10.0, 5.0), row, col, np.arange(n) * 2.0)
    z, y, x = np.mgrid[:n, :16, :14]
    raw = (100 * ((x - 7) ** 2 + (y - 8) ** 2 < 30)).astype(np.int16)
    files = write_series(tmp_path / "ct", raw, row_dir=row, col_dir=col, positions=pos, shuffle_seed=None)
    liver = ((x - 6) ** 2 + (y - 7) ** 2 + (z - 5) ** 2) < 16
    kidney = (x > 10) & (y < 4) & (z > 6)
    scan = volumen.load(tmp_path / "ct")
    f = _seg_from_series(files, [liver, kidney], fractional, tmp_path)
    got = load_labels(f, like=scan)
    assert got.names == {1: "liver", 2: "kidney"}
    np.testing.assert_allclose(got.affine, scan.affine, atol=1e-6)
    # each written mask voxel, placed in the world from its slice's position (DICOM's own geometry), lands on
    # a voxel of the read labels that carries its segment
    for value, m in ((1, liver), (2, kidney)):
        k, r, c = np.nonzero(m)
        lps = pos[k] + (c * 0.6)[:, None] * row + (r * 0.8)[:, None] * col
        ijk = np.linalg.inv(got.affine) @ np.c_[lps * (-1, -1, 1), np.ones(len(k))].T
        idx = np.round(ijk[:3]).astype(int)
        assert np.abs(ijk[:3] - idx).max() < 1e-6
        assert (got.data[idx[2], idx[1], idx[0]] == value).all()
    assert got.counts() == {1: int(liver.sum()), 2: int(kidney.sum())}


def test_dicom_seg_of_another_series(tmp_path):
    from tests.io.dicom_factory import stack_positions, write_series

    row, col = np.array([1.0, 0, 0]), np.array([0, 1.0, 0])
    raw = np.zeros((4, 8, 8), np.int16)
    pos = stack_positions((0, 0, 0), row, col, np.arange(4) * 2.0)
    files = write_series(tmp_path / "a", raw, row_dir=row, col_dir=col, positions=pos, shuffle_seed=None)
    write_series(tmp_path / "b", raw, row_dir=row, col_dir=col, positions=pos, series_uid="1.2.3.4.5",
                 shuffle_seed=None)
    m = np.zeros((4, 8, 8), bool)
    m[1:3, 2:5, 2:5] = True
    f = _seg_from_series(files, [m, m[::-1]], False, tmp_path)
    with pytest.raises(LabelError, match="segments another series") as e:
        load_labels(f, like=volumen.load(tmp_path / "b"))
    assert "\n" not in str(e.value)
