"""Searching a real Orthanc: QIDO-RS and C-FIND find the same studies as Orthanc's own REST listing
(``/tools/find``), by patient name (wildcards), patient ID, date range and modality, over the made studies and
pydicom's test files."""

from __future__ import annotations

import logging

import pytest

import volumen.pacs as pacs

# (volumen's query, the same query in Orthanc's /tools/find terms)
QUERIES = [
    ({"patient_name": "Doe*"}, {"PatientName": "Doe*"}),
    ({"patient_name": "*jane*"}, {"PatientName": "*jane*"}),
    # values that travel percent-encoded (^, a space), which Orthanc 1.10 does not decode
    ({"patient_name": "Doe^Jane"}, {"PatientName": "Doe^Jane"}),
    ({"patient_name": "doe^j*"}, {"PatientName": "doe^j*"}),
    ({"description": "CT chest"}, {"StudyDescription": "CT chest"}),
    ({"patient_id": "PAT-002"}, {"PatientID": "PAT-002"}),
    ({"study_date": "20230101-20241231"}, {"StudyDate": "20230101-20241231"}),
    ({"study_date": "-20011231"}, {"StudyDate": "-20011231"}),
    ({"modality": "MR"}, {"ModalitiesInStudy": "MR"}),
    ({"modality": "CT", "study_date": "20240101-"}, {"ModalitiesInStudy": "CT", "StudyDate": "20240101-"}),
    ({"patient_name": "Doe*", "modality": "CT"}, {"PatientName": "Doe*", "ModalitiesInStudy": "CT"}),
]


@pytest.mark.parametrize("protocol", ["dicomweb", "dimse"])
@pytest.mark.parametrize(("query", "orthanc_query"), QUERIES, ids=[str(q) for q, _ in QUERIES])
def test_find_gives_the_studies_orthanc_lists(archive, archive_config, protocol, query, orthanc_query):
    expected = archive.server.find_studies(orthanc_query)
    found = pacs.find("archive", protocol=protocol, **query)
    assert {s.uid for s in found} == expected
    assert len(found) == len(expected) > 0


def test_all_studies_and_the_made_ones_fields(archive, archive_config):
    everything = archive.server.find_studies({})
    assert len(everything) >= 20  # the made studies and pydicom's
    for protocol in ("dicomweb", "dimse"):
        found = {s.uid: s for s in pacs.find("archive", protocol=protocol)}
        assert set(found) == everything
        chest = found[archive.study_uids["chest"]]
        assert (chest.patient_name, chest.patient_id, chest.date, chest.accession, chest.description) == \
            ("Doe^Jane", "PAT-001", "20240102", "ACC-1", "CT chest")
        assert chest.modalities == ("CT",) and chest.n_series == 2 and chest.n_instances == 11


@pytest.mark.parametrize("protocol", ["dicomweb", "dimse"])
def test_series_of_a_study(archive, archive_config, protocol):
    found = pacs.series("archive", archive.study_uids["chest"], protocol=protocol)
    assert [(s.number, s.modality, s.description, s.n_instances) for s in found] == \
        [("1", "CT", "axial 2 mm", 8), ("2", "CT", "scout", 3)]
    assert [s.uid for s in found] == [s.series_uid for s in archive.series["chest"]]


def test_searches_leave_no_patient_identity_in_the_logs(archive, archive_config, caplog):
    """QIDO's matching values travel in the URL, which urllib3 logs at DEBUG; pynetdicom logs C-FIND identifiers.
    Both are redacted / turned off: the searched and the found names appear in no log record."""
    caplog.set_level(logging.DEBUG)
    for protocol in ("dicomweb", "dimse"):
        found = pacs.find("archive", protocol=protocol, patient_name="Doe*Jane", patient_id="PAT-001")
        assert [s.patient_name for s in found] == ["Doe^Jane"]
    assert "PatientName=..." in caplog.text  # the request was logged, without its value
    for secret in ("Doe", "Jane", "PAT-001"):
        assert secret not in caplog.text


def test_find_returns_a_table_for_the_notebook(archive, archive_config):
    found = pacs.find("archive", patient_id="PAT-003")
    assert isinstance(found, pacs.Studies) and len(found) == 1
    html = found._repr_html_()
    assert html.count("<tr>") == 2 and "<td>Doe^John</td>" in html and f"<td>{found[0].uid}</td>" in html
    assert found.rows()[0][:4] == ["20241120", "MR", "1", "Doe^John"]
