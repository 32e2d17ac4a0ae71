"""Failures against a real Orthanc of this module's own (it is stopped and restarted): each is one line naming
the server (exit 1), never a password or a traceback; a retrieve cut in the middle leaves no half series and a
rerun fetches only what is missing."""

from __future__ import annotations

import os
import threading

import pytest

import volumen
import volumen.pacs as pacs
from tests.pacs.archive_data import PASSWORD_ENV, running_archive, write_servers_toml
from tests.pacs.orthanc_server import PASSWORD, USER, free_port
from volumen.cli import main
from volumen.errors import ArchiveAuthError, ArchiveRefusedError, ArchiveUnreachableError, RetrieveCancelled
from volumen.pacs import _dimse

NAME = "faulty"


@pytest.fixture(scope="module")
def faulty(tmp_path_factory):
    for archive in running_archive(tmp_path_factory, "faulty", with_pydicom=False, DicomCheckCalledAet=True):
        yield archive.server, archive.series


@pytest.fixture
def config(faulty, tmp_path, monkeypatch):
    server, _ = faulty
    if server.process is None:
        server.start()
    monkeypatch.delenv("VOLUMEN_CONFIG_DIR", raising=False)
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "config"))
    monkeypatch.setenv("VOLUMEN_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setenv(PASSWORD_ENV, PASSWORD)
    return write_servers_toml(tmp_path / "config", server, NAME)


def _one_line(capsys, code, expected_code=1) -> str:
    err = capsys.readouterr().err.strip()
    assert code == expected_code, err
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
    return err


def test_server_stopped_mid_retrieve_one_line_nothing_half_written_rerun_resumes(faulty, config, capsys,
                                                                               monkeypatch):
    server, made = faulty
    ct = made["chest"][0]
    write = pacs.SeriesCache.write
    written = []

    def write_then_stop(self, ds):  # the server goes away after the third instance arrived
        path = write(self, ds)
        written.append(path)
        if len(written) == 3:
            server.stop()
        return path

    monkeypatch.setattr(pacs.SeriesCache, "write", write_then_stop)
    code = main(["pacs", "get", NAME, ct.study_uid, ct.series_uid, "--no-progress"])
    err = _one_line(capsys, code)
    assert err.startswith(f"volumen pacs: error: server {NAME} (http://127.0.0.1:") and "did not answer" in err
    where = pacs.SeriesCache(NAME, ct.study_uid, ct.series_uid)
    assert not where.folder.exists()  # no half series under the series' name
    kept = {p.name for p in written}
    assert {p.name for p in where.partial.iterdir()} == kept and len(kept) == 3  # whole files only, no .tmp

    server.start()
    asked = []
    fetch = pacs._dicomweb.DicomWebArchive.fetch
    monkeypatch.setattr(pacs._dicomweb.DicomWebArchive, "fetch",
                        lambda self, st, se, uids, *a: (asked.extend(uids), fetch(self, st, se, uids, *a)))
    assert main(["pacs", "get", NAME, ct.study_uid, ct.series_uid, "--no-progress"]) == 0
    assert len(asked) == 5 and not {f"{u}.dcm" for u in asked} & kept  # only the missing ones
    assert not where.partial.exists() and len(list(where.folder.iterdir())) == 8
    vol, truth = volumen.load(where.folder), volumen.load(ct.folder)
    assert (vol.data == truth.data).all()


def test_cancel_keeps_what_came_and_a_rerun_completes(faulty, config, monkeypatch):
    """Cancelled at 2 of 8: two whole files kept, no series; over C-GET the archive is sent a C-CANCEL, so it stops
    sending (before, it sent all 8, the 6 after the cancel refused one by one)."""
    _, made = faulty
    ct = made["chest"][0]
    cancel = threading.Event()
    arrived = []  # C-STORE sub-operations that reached volumen
    handle = _dimse._Receiver.handle
    monkeypatch.setattr(_dimse._Receiver, "handle", lambda self, event: (arrived.append(1), handle(self, event))[1])

    def progress(done, total):
        if done == 2:
            cancel.set()

    for protocol in ("dicomweb", "dimse"):
        with pytest.raises(RetrieveCancelled, match="cancelled after 2 of 8"):
            pacs.retrieve(NAME, ct.study_uid, ct.series_uid, protocol=protocol, progress=progress, cancel=cancel,
                          refresh=True)
        where = pacs.SeriesCache(NAME, ct.study_uid, ct.series_uid)
        assert len(list(where.partial.iterdir())) == 2 and not where.folder.exists()
        # 3 seen here: the one in flight when the cancel is seen is refused; one more allowed for the C-CANCEL's trip
        assert protocol == "dicomweb" or 3 <= len(arrived) <= 4
        cancel.clear()
        assert len(list(pacs.retrieve(NAME, ct.study_uid, ct.series_uid, protocol=protocol).iterdir())) == 8
        where.forget()


def test_wrong_password_is_one_line_naming_the_server_not_the_password(faulty, config, capsys, monkeypatch):
    wrong = "not-the-password-XYZ"
    monkeypatch.setenv(PASSWORD_ENV, wrong)
    err = _one_line(capsys, main(["pacs", "find", NAME, "--patient", "Doe*"]))
    assert f"server {NAME} (" in err and f"user {USER}" in err and "HTTP 401" in err
    assert wrong not in err and PASSWORD not in err
    with pytest.raises(ArchiveAuthError):
        pacs.echo(NAME)


def test_server_down_and_refused_association(faulty, config, capsys):
    server, _ = faulty
    dead = free_port()
    for target in (f"http://127.0.0.1:{dead}/dicom-web", f"ORTHANC@127.0.0.1:{dead}"):
        err = _one_line(capsys, main(["pacs", "echo", target]))
        assert target in err and "did not answer" in err
    with pytest.raises(ArchiveUnreachableError):
        pacs.find(f"ORTHANC@127.0.0.1:{dead}")
    wrong_aet = f"NOT-ORTHANC@127.0.0.1:{server.dicom_port}"  # this Orthanc checks the called AE title
    err = _one_line(capsys, main(["pacs", "find", wrong_aet]))
    assert "rejected the association" in err
    with pytest.raises(ArchiveRefusedError):
        pacs.echo(wrong_aet)
    assert main(["pacs", "echo", NAME, "--protocol", "dimse"]) == 0
    assert "answers C-ECHO" in capsys.readouterr().out


def test_a_rejection_seen_as_an_abort_is_asked_again(faulty, config, monkeypatch):
    """Under load pynetdicom was seen to report Orthanc's rejection of a wrong called AE title as an abort: the
    association is requested once more before saying which."""
    import pynetdicom

    server, _ = faulty
    associate, calls = pynetdicom.AE.associate, []

    def first_aborted(self, *args, **kwargs):
        calls.append(kwargs["ae_title"])
        if len(calls) == 1:
            return type("Aborted", (), {"is_established": False, "is_rejected": False})()
        return associate(self, *args, **kwargs)

    monkeypatch.setattr(pynetdicom.AE, "associate", first_aborted)
    with pytest.raises(ArchiveRefusedError, match="rejected the association .*its AE title NOT-ORTHANC"):
        pacs.echo(f"NOT-ORTHANC@127.0.0.1:{server.dicom_port}")
    assert calls[:2] == ["NOT-ORTHANC"] * 2 and len(calls) <= 3  # asked again; the real rejection may race too


def test_study_deleted_between_find_and_get(faulty, config, capsys):
    server, made = faulty
    abdomen = made["abdomen"][0]
    assert main(["pacs", "find", NAME, "--patient-id", "PAT-002"]) == 0
    assert abdomen.study_uid in capsys.readouterr().out
    server.delete_study(abdomen.study_uid)
    for protocol in ("dicomweb", "dimse"):
        err = _one_line(capsys, main(["pacs", "get", NAME, abdomen.study_uid, abdomen.series_uid, "--protocol",
                                      protocol, "--no-progress"]))
        assert f"has no series {abdomen.series_uid}" in err and "deleted" in err
        err = _one_line(capsys, main(["pacs", "get", NAME, abdomen.study_uid, "--protocol", protocol]))
        assert f"has no study {abdomen.study_uid}" in err
    assert not pacs.SeriesCache(NAME, abdomen.study_uid, abdomen.series_uid).partial.exists()


def test_secrets_stay_off_the_command_line_and_out_of_readable_files(faulty, config, capsys):
    server, _ = faulty
    url = server.dicomweb_url.replace("http://", f"http://{USER}:{PASSWORD}@")
    err = _one_line(capsys, main(["pacs", "echo", url]))
    assert "password on the command line" in err and PASSWORD not in err
    text = config.read_text().replace(f'password_env = "{PASSWORD_ENV}"', f'password = "{PASSWORD}"')
    config.write_text(text)
    os.chmod(config, 0o644)
    err = _one_line(capsys, main(["pacs", "echo", NAME]))
    assert "others can read it" in err and f"chmod 600 {config}" in err and PASSWORD not in err
    os.chmod(config, 0o600)
    assert main(["pacs", "echo", NAME]) == 0
    assert repr(pacs.resolve_server(NAME)).count(PASSWORD) == 0


def test_a_password_asked_for_once_and_again_after_a_refusal(faulty, config, monkeypatch):
    server, made = faulty
    monkeypatch.setattr(pacs._credentials, "_asked", {})
    bare = pacs.Server(name="asked", url=server.dicomweb_url, username=USER)
    with pytest.raises(pacs._config.ArchiveConfigError, match="user alice has no password"):
        pacs.find(bare, patient_id="PAT-001")  # no terminal to ask in: one line saying where a password goes
    answers, asked = ["not-the-password-XYZ", PASSWORD], []

    def ask(label, user):
        asked.append((label, user))
        return answers[len(asked) - 1]

    with pytest.raises(ArchiveAuthError):
        pacs.find(bare, patient_id="PAT-001", ask=ask)
    found = pacs.find(bare, patient_id="PAT-001", ask=ask)  # the refused one was forgotten: asked again
    chest = made["chest"]
    assert [s.uid for s in found] == [chest[0].study_uid]
    assert [s.uid for s in pacs.series(bare, chest[0].study_uid, ask=ask)] == [s.series_uid for s in chest]
    assert len(list(pacs.retrieve(bare, chest[1].study_uid, chest[1].series_uid, ask=ask).iterdir())) == 3
    assert asked == [(f"asked ({server.dicomweb_url})", USER)] * 2  # remembered after it worked
