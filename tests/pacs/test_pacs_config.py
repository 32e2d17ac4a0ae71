"""Servers, references and queries without a server: servers.toml under XDG_CONFIG_HOME, secrets kept out of
reprs and dicts, references that cannot climb out of the cache, the query string QIDO-RS gets."""

from __future__ import annotations

import json
import os

import pytest

import volumen.pacs as pacs
from volumen.errors import ArchiveConfigError
from volumen.pacs._dicomweb import query_string


@pytest.fixture
def config_home(tmp_path, monkeypatch):
    monkeypatch.delenv("VOLUMEN_CONFIG_DIR", raising=False)
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path))
    (tmp_path / "volumen").mkdir()
    return tmp_path / "volumen" / "servers.toml"


def test_servers_toml_under_xdg_config_home(config_home):
    config_home.write_text('[servers.web]\nurl = "https://pacs.example.org/dicom-web"\nusername = "alice"\n'
                           'password_env = "WEB_PW"\n[servers.scanner]\nae_title = "PACS"\nhost = "pacs.example.org"\n'
                           'port = 104\nretrieve = "move"\nstore_port = 11113\n')
    assert pacs.servers_file() == config_home
    servers = pacs.load_servers()
    assert sorted(servers) == ["scanner", "web"]
    assert servers["web"].kind == "dicomweb" and servers["scanner"].kind == "dimse"
    assert servers["scanner"].label == "scanner (PACS@pacs.example.org:104)"
    assert pacs.Server.from_dict(json.loads(json.dumps(servers["web"].to_dict()))) == servers["web"]
    with pytest.raises(ArchiveConfigError, match="configured: scanner, web"):
        pacs.resolve_server("nowhere")
    with pytest.raises(ArchiveConfigError, match="does not speak DICOMweb"):
        pacs.resolve_server("scanner", protocol="dicomweb")


def test_servers_given_by_address_and_bad_entries(config_home):
    assert pacs.resolve_server("ORTHANC@127.0.0.1:4242").port == 4242
    assert pacs.resolve_server("http://127.0.0.1:8042/dicom-web").kind == "dicomweb"
    with pytest.raises(ArchiveConfigError, match="password on the command line") as info:
        pacs.resolve_server("https://bob:hunter2@pacs.example.org/dicom-web")
    assert "hunter2" not in str(info.value)
    config_home.write_text('[servers.x]\nurl = "https://h/dicom-web"\npasword = "typo"\n')
    with pytest.raises(ArchiveConfigError, match="unknown setting.*pasword"):
        pacs.load_servers()
    config_home.write_text('[servers.x]\nurl = "https://h/dicom-web"\ntoken = "secret-token"\n')
    os.chmod(config_home, 0o640)
    with pytest.raises(ArchiveConfigError, match="others can read it") as info:
        pacs.load_servers()
    assert "secret-token" not in str(info.value)
    os.chmod(config_home, 0o600)
    server = pacs.load_servers()["x"]
    assert "secret-token" not in repr(server) + json.dumps(server.to_dict())


def test_references_and_uids():
    ref = pacs.make_ref("archive", "1.2.3", "1.2.3.4")
    assert ref == "dicomweb://archive/1.2.3/1.2.3.4"
    assert pacs.parse_ref(ref) == ("dicomweb", "archive", "1.2.3", "1.2.3.4")
    assert pacs.parse_ref("dimse://archive/1.2.3") == ("dimse", "archive", "1.2.3", None)
    for bad in ("dicomweb://archive/../../etc", "dicomweb://archive/1.2.3/..", "dicomweb://archive",
                "ftp://archive/1.2/1.3"):
        with pytest.raises(ArchiveConfigError):
            pacs.parse_ref(bad)
    with pytest.raises(ArchiveConfigError):
        pacs.SeriesCache("archive", "1.2", "1.2/../../x")


def test_queries():
    q = pacs.Query(patient_name="Doe*", study_date="20240101-", modality="CT")
    assert q.filters() == {"PatientName": "Doe*", "StudyDate": "20240101-", "ModalitiesInStudy": "CT"}
    for bad in ("2024", "20240101-2024", "-", "yesterday"):
        with pytest.raises(ArchiveConfigError, match="YYYYMMDD"):
            pacs.Query(study_date=bad)
    # wildcards travel as they are (Orthanc 1.10 does not decode %2A); the rest is percent-encoded
    assert query_string({"PatientName": "Doe*Ja?e", "StudyDescription": "CT chest&x=1", "includefield": ["A", "B"]}) \
        == "PatientName=Doe*Ja?e&StudyDescription=CT%20chest%26x%3D1&includefield=A&includefield=B"


def test_cache_keeps_only_listed_instances_and_finishes_by_rename(tmp_path):
    where = pacs.SeriesCache("archive", "1.2", "1.2.3", tmp_path)
    where.partial.mkdir(parents=True)
    for uid in ("1.2.3.1", "1.2.3.2", "1.2.3.9"):
        (where.partial / f"{uid}.dcm").write_bytes(b"x")
    (where.partial / "1.2.3.4.dcm.tmp").write_bytes(b"half")  # a write cut in the middle
    assert where.present() == {"1.2.3.1", "1.2.3.2", "1.2.3.9"} and not where.complete()
    where.keep_only({"1.2.3.1", "1.2.3.2", "1.2.3.4"})  # 1.2.3.9 was deleted on the server since
    assert where.present() == {"1.2.3.1", "1.2.3.2"}
    assert where.finish() == tmp_path / "archive" / "1.2" / "1.2.3" and where.complete()
    assert sorted(p.name for p in where.folder.iterdir()) == ["1.2.3.1.dcm", "1.2.3.2.dcm"]
    assert not where.partial.exists()
