"""``volumen bench render|lighting|mesh --scan FILE``: a scan the benchmark has not seen, benched like its own CTs.

Issue 27 is checked on a CT the benchmark does not have; these tests check what such a scan goes through before
it is timed: read, turned to RAS+ axis order (so VTK's peer draws it too), resampled to the benchmark's sizes as
int16 Hounsfield units, and named scan1, scan2, ... (never after a file or folder, which can carry a patient's
name). No test here times anything.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "io"))  # the DICOM writer of the reader's tests
from dicom_factory import PATIENT, write_series

from volumen.bench import _lighting
from volumen.bench._datasets import SCAN_SIZES, load_scan, scan_datasets
from volumen.bench._mesh import _scan_cases
from volumen.bench._render import bench_render
from volumen.bench._vtk import vtk_available
from volumen.cli import main
from volumen.core import canonical
from volumen.io import load

SHAPE = (12, 24, 20)  # slices, rows, columns


def _series(folder, modality="CT"):
    """A DICOM series stored the way scanners store an axial CT: rows to the patient's left, columns to the
    back (LPS), so its voxel axes i, j point L and P; a sphere of 0 HU (stored +24, intercept -24) in air."""
    z, y, x = np.mgrid[0:SHAPE[0], 0:SHAPE[1], 0:SHAPE[2]]
    raw = (1000 * (((x - 7) ** 2 + (y - 9) ** 2 + (z - 5) ** 2) < 16) - 1000 + 24).astype(np.int16)
    positions = np.array([[-30.0, -40.0, 2.5 * k] for k in range(SHAPE[0])])
    write_series(folder, raw, row_dir=(1, 0, 0), col_dir=(0, 1, 0), positions=positions, patient=PATIENT,
                 intercept=-24.0, modality=modality)
    return folder


@pytest.fixture(scope="module")
def ct_folder(tmp_path_factory):
    return _series(tmp_path_factory.mktemp("scan") / "Doe^Jane_SECRET123_19700101")


def test_a_dicom_ct_is_turned_to_ras_order_and_kept_in_hounsfield_units(ct_folder):
    """As loaded the series' axes point L and P (a negative diagonal in RAS+): VTK's peer would refuse it. The
    scan is benched as ``core.canonical`` turns it (flips: the same samples at the same world points), int16 HU."""
    raw = load(ct_folder)
    assert np.diag(raw.affine)[:2].max() < 0
    vol, offset = load_scan(ct_folder)
    ref = canonical(raw)
    assert offset == 0.0 and vol.data.dtype == np.int16
    assert np.all(np.diag(vol.affine)[:3] > 0)
    np.testing.assert_array_equal(vol.affine, ref.affine)
    np.testing.assert_array_equal(vol.data, ref.data)
    assert set(np.unique(vol.data)) == {-1000, 0}
    # the sphere's centre (voxel 7, 9, 5 as stored) is at the same world point in both
    centre = raw.affine @ [7, 9, 5, 1]
    ijk = np.rint(np.linalg.solve(vol.affine, centre)[:3]).astype(int)
    assert vol.data[ijk[2], ijk[1], ijk[0]] == 0


def test_a_scan_is_resampled_to_a_size_over_the_same_field_of_view(ct_folder):
    vol, _ = load_scan(ct_folder, (10, 12, 6))
    assert vol.shape == (6, 12, 10) and vol.data.dtype == np.int16
    whole = canonical(load(ct_folder))
    np.testing.assert_allclose(np.multiply(vol.shape, vol.spacing), np.multiply(whole.shape, whole.spacing),
                               rtol=1e-9)  # samples x spacing: the field of view (``_datasets.resampled``)
    assert vol.data.min() >= -1000 and vol.data.max() <= 0


def test_scans_are_numbered_never_named_after_their_files(ct_folder):
    sets = scan_datasets([ct_folder, "/data/Doe^John.nii.gz"])
    assert list(sets) == ["scan1-244x202x224", "scan1-366x303x336", "scan2-244x202x224", "scan2-366x303x336"]
    assert sets["scan2-366x303x336"] == ("scan", SCAN_SIZES[1], "/data/Doe^John.nii.gz")
    assert list(scan_datasets(["a.nii"], (None,))) == ["scan1-as-loaded"]


def test_a_colour_file_is_refused_in_one_line():
    from pydicom.data import get_testdata_file

    with pytest.raises(ValueError, match="a colour volume: the benchmarks draw scalar scans"):
        load_scan(get_testdata_file("examples_rgb_color.dcm"))


@pytest.mark.skipif(not vtk_available(), reason="vtk is not installed (pip install 'volumen[bench]')")
def test_bench_render_gives_a_scan_its_ratio_and_bar_with_no_patient_identity(ct_folder, tmp_path):
    table = bench_render(datasets=scan_datasets([ct_folder], ((20, 24, 12),)), images={"32x32": (32, 32)},
                         cases=[("composite", "headlight", "ct-bone", "adaptive")], rounds=1, memory=False,
                         progress=lambda *_: None)
    (row,) = table.rows
    assert row["data"] == "scan1-20x24x12" and row["ct"] and np.isfinite(row["ratio_vtk"])
    assert row["diff_vtk"] < 0.05  # the peer drew the same scan the same way up
    assert any("scan1-20x24x12" in n and "bar <= 0.50 (issue 27)" in n for n in table.notes)
    text = table.render() + json.dumps(json.loads(table.save(tmp_path / "r.json").read_text()))
    for secret in ("Doe", "Jane", "SECRET123", "19700101"):
        assert secret not in text


def test_bench_mesh_takes_a_ct_at_bone_and_another_scan_at_its_otsu_level(ct_folder, tmp_path):
    (name, vol, level_name, level), = _scan_cases([ct_folder], quick=True)
    assert (name, level_name, level) == ("scan1-61x50x56", "bone", 300.0) and vol.shape == (56, 50, 61)
    mr = _series(tmp_path / "mr", modality="MR")
    (_, _, level_name, level), = _scan_cases([mr], quick=True)
    assert level_name == "Otsu" and -1000.0 < level < 0.0


def test_bench_lighting_gives_the_ct_rows_of_a_ct_scan_only(ct_folder, tmp_path, monkeypatch):
    """A CT scan gets the CT rows at the benchmark's size (drawn by ``_ct_rows``, stood in for here: it times
    frames); a scan that is not a CT gets a note."""
    from volumen.bench._table import Table

    calls = []
    monkeypatch.setattr(_lighting, "_ct_rows", lambda table, render, kind, loaded, *a: calls.append(
        (kind, loaded[0].shape, loaded[1])))
    table = Table("t", [("sweep", "sweep", "s")])
    _lighting.real_ct_rows(table, None, quick=True, scans=[ct_folder, _series(tmp_path / "mr", modality="MR")])
    assert calls == [("scan1", (42, 38, 46), 0.0)]
    assert table.notes == ["scan2: not a CT in Hounsfield units: no CT rows (the bars are for CTs)"]


@pytest.mark.parametrize(("argv", "needle"), [
    (["bench", "compile", "--scan", "x.nii"], "--scan is for bench render, lighting, mesh, not compile"),
    (["bench", "render", "--scan", "/no/such/scan.nii.gz", "--no-vtk"], "--scan: no such file or folder"),
])
def test_the_command_line_refuses_a_bad_scan_in_one_line(argv, needle, capsys):
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert needle in err and "Traceback" not in err and len(err.strip().splitlines()) == 1
