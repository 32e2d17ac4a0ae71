"""Retrieving from a real Orthanc: a series fetched over WADO-RS, C-GET and C-MOVE loads to the very voxels
and geometry of the files uploaded; ``dicomweb://`` references load through the cache; a SEG sent with
STOW-RS and a secondary capture sent with C-STORE are found again by QIDO-RS and C-FIND."""

from __future__ import annotations

import numpy as np
import pydicom
import pytest

import volumen
import volumen.pacs as pacs


def _same_volume(a, b):
    assert a.shape == b.shape
    assert np.array_equal(np.asarray(a.data), np.asarray(b.data))
    np.testing.assert_allclose(a.affine, b.affine, atol=1e-6)


@pytest.mark.parametrize(("protocol", "via"), [("dicomweb", "get"), ("dimse", "get"), ("dimse", "move")])
def test_retrieved_series_loads_to_the_uploaded_voxels(archive, archive_config, tmp_path, protocol, via):
    ct = archive.ct
    server = pacs.resolve_server("archive", protocol=protocol)
    server = pacs.Server.from_dict({**server.to_dict(), "retrieve": via})
    seen = []
    folder = pacs.retrieve(server, ct.study_uid, ct.series_uid, cache=tmp_path / "cache",
                           progress=lambda done, total: seen.append((done, total)))
    uploaded = {f"{pydicom.dcmread(p, stop_before_pixels=True).SOPInstanceUID}.dcm" for p in ct.folder.iterdir()}
    assert {p.name for p in folder.iterdir()} == uploaded and len(uploaded) == ct.n == 8
    assert seen[0] == (0, 8) and seen[-1] == (8, 8) and len(seen) == 9
    _same_volume(volumen.load(folder), volumen.load(ct.folder))
    assert not any(p.name.endswith(".partial") for p in folder.parent.iterdir())


def test_a_cached_series_is_not_fetched_again(archive, archive_config, monkeypatch):
    ct = archive.ct
    ref = pacs.make_ref("archive", ct.study_uid, ct.series_uid)
    first = volumen.load(ref)
    _same_volume(first, volumen.load(ct.folder))
    assert first.meta["archive_ref"] == ref

    def no_network(*a, **k):
        raise AssertionError("the cached series was fetched again")

    monkeypatch.setattr(pacs._dicomweb.DicomWebArchive, "fetch", no_network)
    monkeypatch.setattr(pacs._dicomweb.DicomWebArchive, "list_instances", no_network)
    _same_volume(volumen.load(ref), first)


def test_a_study_reference_needs_a_series_when_it_holds_several(archive, archive_config):
    from volumen.errors import MultipleSeriesError

    with pytest.raises(MultipleSeriesError) as info:
        volumen.load(f"dicomweb://archive/{archive.study_uids['chest']}")
    assert archive.series["chest"][1].series_uid in str(info.value)
    scout = archive.series["chest"][1]
    _same_volume(volumen.load(f"dicomweb://archive/{scout.study_uid}", series=scout.series_uid),
                 volumen.load(scout.folder))  # what --series UID passes
    head = archive.series["head"][0]
    vol = volumen.load(f"dimse://archive/{head.study_uid}")  # one series: no choice to make
    _same_volume(vol, volumen.load(head.folder))


def test_seg_sent_with_stow_is_found_by_qido_and_reads_back(archive, archive_config, tmp_path):
    ct = archive.ct
    scan = volumen.load(pacs.make_ref("archive", ct.study_uid, ct.series_uid))
    mask = np.asarray(scan.data) > 1200
    assert 0 < mask.sum() < mask.size
    seg = pacs.make_seg(mask, scan)
    before = {s.uid for s in pacs.series("archive", ct.study_uid)}
    assert pacs.send("archive", [seg]) == 1
    try:
        assert archive.server.find_studies({"ModalitiesInStudy": "SEG"}) >= {ct.study_uid}
        for protocol in ("dicomweb", "dimse"):
            assert ct.study_uid in {s.uid for s in pacs.find("archive", modality="SEG", protocol=protocol)}
        added = [s for s in pacs.series("archive", ct.study_uid) if s.uid not in before]
        assert [(s.uid, s.modality, s.n_instances) for s in added] == [(seg.SeriesInstanceUID, "SEG", 1)]
        folder = pacs.retrieve("archive", ct.study_uid, seg.SeriesInstanceUID)
        labels = volumen.load_labels(next(folder.iterdir()), like=scan)
        assert np.array_equal(labels.data.astype(bool), mask) and labels.names == {1: "lumen"}
    finally:
        archive.server.rest("delete", f"/series/{_orthanc_series(archive.server, seg.SeriesInstanceUID)}")


def test_capture_sent_with_c_store_is_found_by_c_find(archive, archive_config):
    head = archive.series["head"][0]
    scan = volumen.load(head.folder)
    picture = np.zeros((24, 32, 3), np.uint8)
    picture[4:20, 8:24] = (200, 120, 40)
    sc = pacs.make_capture(picture, scan)
    assert pacs.send("archive", [sc], protocol="dimse") == 1
    try:
        found = pacs.series("archive", head.study_uid, protocol="dimse")
        assert sc.SeriesInstanceUID in {s.uid for s in found}
        folder = pacs.retrieve("archive", head.study_uid, sc.SeriesInstanceUID, protocol="dimse")
        back = volumen.load(folder)
        assert back.is_color and np.array_equal(np.asarray(back.data)[0], picture)
    finally:
        archive.server.rest("delete", f"/series/{_orthanc_series(archive.server, sc.SeriesInstanceUID)}")


def _orthanc_series(server, uid: str) -> str:
    found = server.rest("post", "/tools/lookup", data=uid).json()
    return next(x["ID"] for x in found if x["Type"] == "Series")


def test_info_on_an_archive_reference_prints_no_patient_identity(archive, archive_config, capsys):
    from volumen.cli import main

    ref = pacs.make_ref("archive", archive.ct.study_uid, archive.ct.series_uid)
    for extra in ([], ["--json"]):
        assert main(["info", ref, *extra]) == 0
        out = capsys.readouterr()
        assert archive.ct.series_uid in out.out and "20 x 24 x 8 voxels" in out.out or extra
        for secret in ("Doe", "Jane", "PAT-001", "ACC-1", "CT chest"):
            assert secret not in out.out and secret not in out.err


@pytest.mark.parametrize("protocol", ["dicomweb", "dimse"])
@pytest.mark.parametrize("name", ["693_J2KI.dcm", "examples_jpeg2k.dcm", "SC_rgb_gdcm_KY.dcm"])
def test_compressed_instances_arrive_as_stored(archive, archive_config, tmp_path, protocol, name):
    """pydicom's JPEG 2000 CT, ultrasound and colour files: C-GET proposes a context per transfer syntax for the
    series' SOP classes (Orthanc cannot transcode from JPEG 2000), so both protocols deliver the stored syntax and
    the reader gets the original's values."""
    from tests.pacs.archive_data import pydicom_files

    original = next(p for p in pydicom_files() if p.name == name)
    ds = pydicom.dcmread(original, stop_before_pixels=True)
    folder = pacs.retrieve("archive", ds.StudyInstanceUID, ds.SeriesInstanceUID, protocol=protocol, cache=tmp_path)
    got = folder / f"{ds.SOPInstanceUID}.dcm"
    assert pydicom.dcmread(got, stop_before_pixels=True).file_meta.TransferSyntaxUID == ds.file_meta.TransferSyntaxUID
    assert np.array_equal(np.asarray(volumen.load(got).data), np.asarray(volumen.load(original).data))
