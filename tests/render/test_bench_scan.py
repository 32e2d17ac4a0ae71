"""``volumen bench render|lighting|mesh --scan FILE``: a scan the benchmark has not seen, benched like its own CTs.

The speed bars are checked on CTs the benchmark does not have too; these tests check what such a scan goes
through before it is timed: read, turned to RAS+ axis order (so VTK's peer draws it too), resampled to the
benchmark's sizes as int16 Hounsfield units, and named scan1, scan2, ... (never after a file or folder, which can
carry a patient's name). No test here times anything.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from tests.io.dicom_factory import PATIENT, write_series
from volumen.bench import _lighting
from volumen.bench._datasets import SCAN_SIZES, read_scan, scan_at, scan_datasets
from volumen.bench._mesh import _scan_cases, bench_mesh
from volumen.bench._render import bench_render
from volumen.bench._vtk_peer import vtk_available
from volumen.cli import main
from volumen.core import canonical
from volumen.io import load

SHAPE = (12, 24, 20)  # slices, rows, columns
SECRETS = ("Doe", "Jane", "SECRET123", "19700101")


def _series(folder, modality="CT", bone=True, row_dir=(1, 0, 0), col_dir=(0, 1, 0), n=SHAPE[0], uid=None,
            prefix="IM"):
    """A DICOM series stored the way scanners store an axial CT: rows to the patient's left, columns to the
    back (LPS), so its voxel axes i, j point L and P; a sphere of 0 HU (stored +24, intercept -24) in air, and
    a bar of bone (700 HU) in one corner."""
    z, y, x = np.mgrid[0:n, 0:SHAPE[1], 0:SHAPE[2]]
    hu = 1000 * (((x - 7) ** 2 + (y - 9) ** 2 + (z - 5) ** 2) < 16) - 1000
    if bone:
        hu = np.where((x >= 15) & (y < 5), 700, hu)
    normal = np.cross(row_dir, col_dir)
    positions = np.array([np.add([-30.0, -40.0, 0.0], 2.5 * k * normal) for k in range(n)])
    write_series(folder, (hu + 24).astype(np.int16), row_dir=row_dir, col_dir=col_dir, positions=positions,
                 patient=PATIENT, intercept=-24.0, modality=modality, series_uid=uid, prefix=prefix)
    return folder


@pytest.fixture(scope="module")
def ct_folder(tmp_path_factory):
    return _series(tmp_path_factory.mktemp("scan") / "Doe^Jane_SECRET123_19700101")


def test_a_dicom_ct_is_turned_to_ras_order_and_kept_in_hounsfield_units(ct_folder):
    """As loaded the series' axes point L and P (a negative diagonal in RAS+): VTK's peer would refuse it. The
    scan is benched as ``core.canonical`` turns it (flips: the same samples at the same world points), int16 HU,
    named by its number."""
    raw = load(ct_folder)
    assert np.diag(raw.affine)[:2].max() < 0
    scan = read_scan(ct_folder, 3)
    vol, offset = scan_at(scan, None)
    ref = canonical(raw)
    assert offset == 0.0 and vol.data.dtype == np.int16 and vol.name == "scan3" and not any(vol.meta.values())
    assert np.all(np.diag(vol.affine)[:3] > 0)
    np.testing.assert_array_equal(vol.affine, ref.affine)
    np.testing.assert_array_equal(vol.data, ref.data)
    assert set(np.unique(vol.data)) == {-1000, 0, 700}
    # the sphere's centre (voxel 7, 9, 5 as stored) is at the same world point in both
    centre = raw.affine @ [7, 9, 5, 1]
    ijk = np.rint(np.linalg.solve(vol.affine, centre)[:3]).astype(int)
    assert vol.data[ijk[2], ijk[1], ijk[0]] == 0


def test_an_oblique_scan_is_laid_on_an_axis_aligned_grid_the_vtk_peer_takes(tmp_path):
    """A series tilted 15 degrees about the patient's left-right axis: its rotation is dropped (the samples
    and spacing kept), so VTK's peer, which takes axis-aligned RAS+ grids only, draws it."""
    c, s = np.cos(np.radians(15)), np.sin(np.radians(15))
    folder = _series(tmp_path / "tilted", col_dir=(0, c, s))
    vol, offset = scan_at(read_scan(folder), None)
    m = np.asarray(vol.affine)[:3, :3]
    assert offset == 0.0 and np.array_equal(m, np.diag(np.diag(m))) and np.all(np.diag(m) > 0)
    np.testing.assert_array_equal(vol.data, canonical(load(folder)).data)
    if vtk_available():
        from volumen.bench._render import _scene
        from volumen.bench._vtk_peer import VtkScene
        from volumen.core import Camera

        VtkScene(_scene(vol, "composite", "headlight", "ct-bone", 0.0, 1.0), Camera.orbit(vol), (8, 8))


def test_a_scan_is_resampled_to_a_size_over_the_same_field_of_view(ct_folder):
    vol, _ = scan_at(read_scan(ct_folder), (10, 12, 6))
    assert vol.shape == (6, 12, 10) and vol.data.dtype == np.int16
    whole = canonical(load(ct_folder))
    np.testing.assert_allclose(np.multiply(vol.shape, vol.spacing), np.multiply(whole.shape, whole.spacing),
                               rtol=1e-9)  # samples x spacing: the field of view (``_datasets.resampled``)
    assert vol.data.min() >= -1000 and vol.data.max() <= 700


def test_a_large_scan_is_thinned_before_it_is_resampled(ct_folder):
    """A source over twice the asked size along an axis is read every k-th sample first (no float copy of the
    whole grid): 24 rows to 5 keeps every 2nd (12 rows, at most twice 5), the same field of view."""
    scan = read_scan(ct_folder)
    vol, _ = scan_at(scan, (5, 5, 6))
    assert vol.shape == (6, 5, 5)
    np.testing.assert_allclose(np.multiply(vol.shape, vol.spacing), np.multiply(SHAPE, scan[0].spacing), rtol=1e-9)


def test_scans_are_numbered_never_named_after_their_files(ct_folder):
    scan = read_scan(ct_folder)
    sets = scan_datasets([scan, scan])
    assert list(sets) == ["scan1-244x202x224", "scan1-366x303x336", "scan2-244x202x224", "scan2-366x303x336"]
    assert sets["scan2-366x303x336"][:2] == ("scan", SCAN_SIZES[1])
    assert list(scan_datasets([scan], (None,))) == ["scan1-as-loaded"]


def test_a_folder_of_several_series_gives_its_series_of_most_slices(tmp_path):
    folder = tmp_path / "Doe^Jane_SECRET123"
    _series(folder, uid="1.2.826.0.1.3680043.8.498.1", n=3, bone=False, prefix="SCOUT")
    _series(folder, uid="1.2.826.0.1.3680043.8.498.2")
    vol, _ = read_scan(folder)
    assert vol.shape == SHAPE and vol.data.max() == 700


@pytest.mark.parametrize(("make", "needle"), [
    (lambda d: (d / "Doe^Jane.nii.gz").write_bytes(b"not a volume") and d / "Doe^Jane.nii.gz", "scan2: "),
    (lambda d: __import__("pydicom.data").data.get_testdata_file("examples_rgb_color.dcm"),
     "scan2: a colour volume: the benchmarks draw scalar volumes"),
    (lambda d: __import__("pydicom.data").data.get_testdata_file("CT_small.dcm"),
     "scan2: a slab of 128x128x1 voxels"),
])
def test_a_scan_that_cannot_be_benched_is_refused_in_one_line_without_its_path(tmp_path, make, needle):
    path = make(tmp_path)
    with pytest.raises(ValueError) as err:
        read_scan(path, 2)
    text = str(err.value)
    assert text.startswith(needle) and "\n" not in text and "Doe" not in text and str(tmp_path) not in text


@pytest.mark.skipif(not vtk_available(), reason="vtk is not installed (pip install 'volumen[bench]')")
def test_bench_render_gives_a_scan_its_ratio_and_bar_with_no_patient_identity(ct_folder, tmp_path):
    table = bench_render(datasets=scan_datasets([read_scan(ct_folder)], ((20, 24, 12),)),
                         images={"32x32": (32, 32)}, cases=[("composite", "headlight", "ct-bone", "default")],
                         rounds=1, memory=False, progress=lambda *_: None)
    (row,) = table.rows
    assert row["data"] == "scan1-20x24x12" and row["ct"] and np.isfinite(row["ratio_vtk"])
    assert row["diff_vtk"] < 0.05  # the peer drew the same scan the same way up
    assert any("scan1-20x24x12" in n and "bar <= 0.50 (issue 27)" in n for n in table.notes)
    text = table.render() + json.dumps(json.loads(table.save(tmp_path / "r.json").read_text()))
    assert not any(secret in text for secret in SECRETS)


def test_the_command_line_benches_the_scan_alone_and_prints_no_patient_identity(ct_folder, tmp_path, capsys):
    """``--scan`` without ``--data``: the scan's rows only (none of the built-in data sets'), at the quick size;
    nothing printed, written or raised names the patient."""
    out = tmp_path / "bench"
    assert main(["bench", "render", "--scan", str(ct_folder), "--quick", "--no-vtk", "--repeat", "1",
                 "--out", str(out)]) == 0
    printed = capsys.readouterr()
    rows = json.loads((out / "render-quick.json").read_text())["rows"]
    assert {r["data"] for r in rows} == {"scan1-61x51x56"} and len(rows) == 8
    text = printed.out + printed.err + (out / "render-quick.md").read_text()
    assert "scan1-61x51x56" in printed.out and not any(secret in text for secret in SECRETS)


def test_bench_mesh_takes_a_ct_at_bone_and_another_scan_at_its_otsu_level(ct_folder, tmp_path):
    table = bench_mesh(quick=True, rounds=1, scans=[read_scan(ct_folder)], progress=lambda *_: None)
    (row,) = table.rows
    assert row["data"] == "scan1-61x50x56" and row["level"] == "bone 300" and row["ours_tris"] > 0
    if "vtk_tris" in row:
        assert abs(row["ours_tris"] - row["vtk_tris"]) <= 0.01 * row["vtk_tris"]
    said = []
    mr = read_scan(_series(tmp_path / "mr", modality="MR"))
    soft = read_scan(_series(tmp_path / "soft", bone=False))
    cases = list(_scan_cases([mr, soft], True, said.append))
    assert [(c[0], c[2]) for c in cases] == [("scan1-61x50x56", "Otsu")]
    assert said == ["scan2-61x50x56: no surface at bone 300 (values -1000..0): skipped"]


def test_bench_lighting_gives_the_ct_rows_of_a_ct_scan_only(ct_folder, tmp_path, monkeypatch):
    """A CT scan gets the CT rows at the benchmark's size (drawn by ``_ct_rows``, stood in for here: it times
    frames), and nothing else of the benchmark; a scan that is not a CT gets a note."""
    calls = []
    monkeypatch.setattr(_lighting, "_ct_rows", lambda table, render, kind, loaded, *a: calls.append(
        (kind, loaded[0].shape, loaded[1])))
    mr = read_scan(_series(tmp_path / "mr", modality="MR"), 2)
    table = _lighting.bench_lighting(quick=True, scans=[read_scan(ct_folder), mr], progress=lambda *_: None)
    assert calls == [("scan1", (42, 38, 46), 0.0)] and table.rows == []
    assert table.notes[-1] == "scan2: not a CT in Hounsfield units: no CT rows (the bars are for CTs)"


@pytest.mark.parametrize(("argv", "needle"), [
    (["bench", "compile", "--scan", "x.nii"], "--scan is for bench render, lighting, mesh, not compile"),
    (["bench", "render", "--scan", "/no/such/Doe^Jane.nii.gz", "--no-vtk"], "--scan 1 (scan1): no such file"),
])
def test_the_command_line_refuses_a_bad_scan_in_one_line(argv, needle, capsys):
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert needle in err and "Traceback" not in err and len(err.strip().splitlines()) == 1 and "Doe" not in err
