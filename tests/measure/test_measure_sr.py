"""Measurements exchanged: a DICOM Comprehensive 3D SR read back by highdicom and pydicom with every measurement,
its UCUM unit and its references; session JSON, JSON and CSV; ``volumen measure export``; bad input in one line."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pydicom
import pytest

import volumen
from tests.io.dicom_factory import new_uid, oblique_cosines, stack_positions, write_series
from volumen import measure
from volumen.cli import main
from volumen.core import LabelMap
from volumen.errors import MeasurementError


def _write_ct(folder, study_uid=None, seed=1):
    """A small oblique CT series (8 slices of 40 x 50, 0.8 x 0.6 mm, 2.5 mm apart) in ``folder``."""
    raw = (np.random.default_rng(seed).normal(40, 30, (8, 40, 50))).astype(np.int16)
    row, col = oblique_cosines(degrees=15.0)
    normal = np.cross(row, col)
    pos = stack_positions((-15.0, -12.0, 30.0), row, col, np.arange(8) * 2.5)
    patient = {"PatientName": "Anonymous^", "PatientID": "0"}
    if study_uid:
        patient["StudyInstanceUID"] = study_uid
    write_series(folder, raw, row_dir=row, col_dir=col, positions=pos, patient=patient,
                 series_uid=new_uid(f"measure-{folder}"))
    assert normal is not None
    return volumen.load(folder)


@pytest.fixture(scope="module")
def ct(tmp_path_factory):
    return _write_ct(tmp_path_factory.mktemp("ct") / "series")


def _items(vol):
    plane = measure.slice_plane(vol, "axial", 3)
    c = vol.center
    labels = LabelMap((np.asarray(vol.data) > 60).astype(np.uint8), affine=vol.affine, names={1: "bright"})
    return measure.Measurements([
        measure.distance(c - (5, 2, 1), c + (6, 3, 0), volume=vol, label="ruler a"),
        measure.angle(c + (4, 0, 0), c, c + (0, 5, 1), volume=vol),
        measure.point(c + (1, 1, 1), volume=vol, label="landmark"),
        measure.roi_stats(vol, plane, measure.Ellipse((15.0, 12.0), (6.0, 4.0)), label="liver"),
        measure.roi_stats(vol, plane, measure.Rectangle((3.0, 4.0), (12.0, 10.0))),
        measure.roi_stats(vol, plane, measure.Polygon(((2.0, 2.0), (20.0, 5.0), (9.0, 18.0)))),
        *measure.label_volumes(labels, scan=vol),
    ])


def _same(a, b):
    """Two measurements agree: kind, label, world points to a micrometre, numbers to 1e-6 relative (an SR keeps
    coordinates as 32-bit floats, so lengths and angles recomputed from them carry float32 rounding)."""
    assert (a.kind, a.label) == (b.kind, b.label)
    if hasattr(a, "points"):
        np.testing.assert_allclose(np.asarray(a.points), np.asarray(b.points), atol=1e-3)
    for name in ("mm", "degrees", "mean", "sd", "min", "max", "median", "area_mm2", "voxels", "ml", "units", "value"):
        if hasattr(a, name):
            va, vb = getattr(a, name), getattr(b, name)
            assert va == pytest.approx(vb, rel=1e-6) if isinstance(va, float) else va == vb, name
    if a.kind == "region":
        assert a.shape.kind == b.shape.kind


def test_sr_reads_back_with_every_measurement_unit_and_reference(ct, tmp_path):
    import highdicom as hd

    items = _items(ct)
    path = tmp_path / "report.dcm"
    measure.make_sr(items, ct).save_as(path, enforce_file_format=True)

    ds = pydicom.dcmread(path)  # a valid SR IOD: its modules' type 1 attributes and the TID 1500 root
    assert ds.SOPClassUID == pydicom.uid.Comprehensive3DSRStorage and ds.Modality == "SR"
    assert ds.file_meta.MediaStorageSOPClassUID == ds.SOPClassUID
    assert (ds.ValueType, ds.CompletionFlag, ds.VerificationFlag) == ("CONTAINER", "COMPLETE", "UNVERIFIED")
    assert ds.ConceptNameCodeSequence[0].CodeValue == "126000"
    assert ds.ContentTemplateSequence[0].TemplateIdentifier == "1500"
    sources = measure._sr_write._sources(ct)
    assert ds.StudyInstanceUID == sources[0].StudyInstanceUID and ds.SeriesInstanceUID != ct.meta["series_uid"]
    (study,) = ds.CurrentRequestedProcedureEvidenceSequence
    (series,) = study.ReferencedSeriesSequence
    assert series.SeriesInstanceUID == ct.meta["series_uid"]
    assert {r.ReferencedSOPInstanceUID for r in series.ReferencedSOPSequence} == {s.SOPInstanceUID for s in sources}

    report = hd.sr.srread(path).content
    planar = report.get_planar_roi_measurement_groups()
    assert len(planar) == 6 and len(report.get_image_measurement_groups()) == 1
    units = {(str(m.name.meaning), str(m.unit.value)) for g in planar for m in g.get_measurements()}
    assert {("Length", "mm"), ("Angle", "deg"), ("Mean", "[hnsf'U]"), ("Standard Deviation", "[hnsf'U]"),
            ("Area", "mm2"), ("Count", "{voxels}")} <= units
    assert {g.roi.frame_of_reference_uid for g in planar} == {sources[0].FrameOfReferenceUID}
    for g in planar[3:6]:  # the regions on axial slice 3: every number references that slice's image
        refs = {r.referenced_sop_instance_uid for m in g.get_measurements() for r in m.referenced_images}
        assert refs == {sources[3].SOPInstanceUID}
    volume_units = {str(m.unit.value) for m in report.get_image_measurement_groups()[0].get_measurements()}
    assert volume_units == {"ml", "{voxels}"}

    back = volumen.load_measurements(path, volume=ct)
    assert len(back) == len(items)
    for a, b in zip(items, back, strict=True):
        _same(a, b)


def test_json_session_and_csv_round_trip(ct, tmp_path):
    items = _items(ct)
    measure.save_measurements(items, tmp_path / "m.json")
    assert volumen.load_measurements(tmp_path / "m.json", volume=ct) == items
    session = {"version": 1, "scene": {"volume": ct.meta["source"]}, measure.SESSION_KEY: items.to_dicts()}
    assert measure.session_measurements(json.loads(json.dumps(session))) == items
    measure.save_measurements(items, tmp_path / "m.csv")
    lines = (tmp_path / "m.csv").read_text().splitlines()
    assert len(lines) == len(items) + 1 and lines[1].startswith("distance,ruler a,")


def test_a_measurement_of_another_scan_is_one_line(ct, tmp_path):
    other = _write_ct(tmp_path / "other", seed=2)
    ruler = measure.distance((0, 0, 0), (1, 0, 0), volume=other)
    with pytest.raises(MeasurementError) as err:
        measure.make_sr([ruler], ct)
    assert "\n" not in str(err.value) and other.meta["series_uid"] in str(err.value)


def test_an_sr_of_another_study_is_one_line(ct, tmp_path):
    path = tmp_path / "report.dcm"
    measure.make_sr(_items(ct)[:2], ct).save_as(path, enforce_file_format=True)
    elsewhere = _write_ct(tmp_path / "elsewhere", study_uid=new_uid("another-study"), seed=3)
    with pytest.raises(MeasurementError) as err:
        volumen.load_measurements(path, volume=elsewhere)
    assert "\n" not in str(err.value) and "an SR of study" in str(err.value)


def _session(tmp_path, vol, items) -> Path:
    path = tmp_path / "session.json"
    path.write_text(json.dumps({"version": 1, "scene": {"volume": str(vol.meta["source"])},
                                measure.SESSION_KEY: items.to_dicts()}))
    return path


def test_cli_export_writes_sr_csv_and_json(ct, tmp_path, capsys):
    items = _items(ct)
    session = _session(tmp_path, ct, items)
    for name in ("report.dcm", "report.csv", "report.json"):
        assert main(["measure", "export", str(session), "-o", str(tmp_path / name)]) == 0
        assert f"wrote {len(items)} measurement(s)" in capsys.readouterr().out
    assert len(volumen.load_measurements(tmp_path / "report.dcm", volume=ct)) == len(items)
    assert volumen.load_measurements(tmp_path / "report.json") == items


def test_cli_export_of_another_scans_measurements_is_one_line_and_writes_nothing(ct, tmp_path, capsys):
    other = _write_ct(tmp_path / "other", seed=4)
    session = _session(tmp_path, ct, measure.Measurements([measure.distance((0, 0, 0), (1, 1, 1), volume=other)]))
    out = tmp_path / "out" / "report.dcm"
    assert main(["measure", "export", str(session), "-o", str(out)]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("volumen measure: error: ") and "not on the scan loaded" in err[0]
    assert not (tmp_path / "out").exists()


def test_sr_sent_to_the_archive_is_found_by_qido(archive, archive_config, tmp_path, capsys):
    import volumen.pacs as pacs

    made = archive.ct
    scan = volumen.load(made.folder)
    path = tmp_path / "report.dcm"
    session = _session(tmp_path, scan, measure.Measurements([measure.distance(scan.center, scan.center + 3,
                                                                              volume=scan, label="sent")]))
    assert main(["measure", "export", str(session), "-o", str(path)]) == 0
    sr_series = pydicom.dcmread(path).SeriesInstanceUID
    assert main(["pacs", "send", "archive", str(path)]) == 0
    try:
        assert made.study_uid in {s.uid for s in pacs.find("archive", modality="SR", protocol="dicomweb")}
        found = {s.uid: s.modality for s in pacs.series("archive", made.study_uid, protocol="dicomweb")}
        assert found.get(sr_series) == "SR"
        folder = pacs.retrieve("archive", made.study_uid, sr_series)
        (back,) = volumen.load_measurements(next(folder.iterdir()), volume=scan)
        assert back.label == "sent" and back.mm == pytest.approx(3 * np.sqrt(3), rel=1e-6)  # float32 coordinates
    finally:
        ids = archive.server.rest("post", "/tools/lookup", data=sr_series).json()
        for hit in ids:
            archive.server.rest("delete", f"/series/{hit['ID']}")
