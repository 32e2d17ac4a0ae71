"""The archive client against a hostile DICOMweb archive (``tools.fuzz.net.HostileArchive``, a local HTTP server
answering what it is told): terminal escapes and line ends in fields are escaped in ``find``'s table (``--json``
stays exact), odd answer shapes are one line and exit 1, a 400 MB answer and a dribbling server end in one line
within the deadline, a redirect to another host and credentials in a URL are refused."""

from __future__ import annotations

import json
import time

import pytest

from tools.fuzz.net import HostileArchive, Reply, dataset_json, endless
from volumen.cli import main
from volumen.errors import ArchiveConfigError
from volumen.pacs import resolve_server

UID = "1.2.3.4"
EVIL_NAME = "Doe\x1b]0;pwned\x07\x1b[2J\x1b[H^Jane"
EVIL_ID = "ID1\r\n2024  CT  1  Forged^Row  X"


@pytest.fixture
def archive():
    with HostileArchive() as a:
        yield a


@pytest.fixture
def config(tmp_path, monkeypatch):
    """A servers.toml of one server, ``hostile``, with the given settings (an empty cache of its own)."""
    monkeypatch.delenv("VOLUMEN_CONFIG_DIR", raising=False)
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "config"))
    monkeypatch.setenv("VOLUMEN_CACHE_DIR", str(tmp_path / "cache"))

    def write(url: str, **settings) -> str:
        folder = tmp_path / "config" / "volumen"
        folder.mkdir(parents=True, exist_ok=True)
        lines = ["[servers.hostile]", f'url = "{url}"', *(f"{k} = {v}" for k, v in settings.items())]
        (folder / "servers.toml").write_text("\n".join(lines) + "\n")
        return "hostile"

    return write


def _one_line(capsys, code) -> str:
    out, err = capsys.readouterr()
    assert code == 1, (code, err)
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err and "internal error" not in err, err
    return err.strip()


def test_escapes_and_line_ends_are_escaped_in_the_table(archive, capsys):
    """A patient name holding terminal escapes (set the title, clear the screen) and a patient ID holding
    ``\\r\\n`` and a forged row: the table shows them escaped on one row; ``--json`` gives them exactly."""
    archive.reply = Reply(json.dumps([dataset_json(PatientName=EVIL_NAME, PatientID=EVIL_ID, StudyInstanceUID=UID,
                                                   StudyDescription="tab\there\u202eevil")]).encode())
    assert main(["pacs", "find", archive.url]) == 0
    out, _ = capsys.readouterr()
    assert "\x1b" not in out and "\r" not in out and "\u202e" not in out and "\t" not in out
    assert len(out.strip().splitlines()) == 2   # the header and one study
    assert "\\x1b]0;pwned\\x07" in out and "ID1\\x0d\\x0a2024" in out
    assert main(["pacs", "find", archive.url, "--json"]) == 0
    found = json.loads(capsys.readouterr().out)
    assert found[0]["patient_name"] == EVIL_NAME and found[0]["patient_id"] == EVIL_ID


@pytest.mark.parametrize("body", [b'{"a":1}', b"42", b'"x"', b"[1, 2]", b"[[]]", b'[{"00100010": 5}]',
                                  b'[{"00100010": {"vr": 1}}]', b'[{"0020000D": {"vr": "UI", "Value": 7}}]',
                                  b'[{"00100010": {"vr": "PN", "Value": [{"Alphabetic": 5}]}}]', b"[" * 5000,
                                  b"not json", b"\xff\xfe", b"null", b"true"])
def test_odd_answer_shapes_are_one_line_exit_1(archive, capsys, body):
    """A search answer that is not a list of DICOM JSON datasets: one line naming the server, exit 1 (before:
    'internal error: TypeError', exit 3)."""
    archive.reply = Reply(body)
    err = _one_line(capsys, main(["pacs", "find", archive.url]))
    assert err.startswith("volumen pacs: error: server ")


def test_odd_series_answers_are_one_line(archive, capsys):
    archive.reply = Reply(b'{"0020000E": 3}')
    _one_line(capsys, main(["pacs", "find", archive.url, "--study", UID]))
    archive.reply = Reply(b"[{}]")   # a series without a UID: listed, nothing breaks
    assert main(["pacs", "find", archive.url, "--study", UID]) == 0


def test_a_400_mb_answer_is_refused_at_the_cap(archive, capsys):
    """An endless search answer (400 MB and more, no Content-Length): refused in one line at max_answer_mb (64 MiB
    by default), not read whole; a declared Content-Length past the cap is refused before reading."""
    archive.reply = Reply(endless(json.dumps(dataset_json(PatientName="A" * 60, StudyInstanceUID=UID)).encode()
                                  + b",", b"["))
    t0 = time.perf_counter()
    err = _one_line(capsys, main(["pacs", "find", archive.url]))
    print(f"endless answer: {err} ({time.perf_counter() - t0:.1f} s)")
    assert "more than 64 MiB" in err and "max_answer_mb" in err
    archive.reply = Reply(lambda: iter([b"[]"]), headers={"Content-Length": str(400 << 20)})
    err = _one_line(capsys, main(["pacs", "find", archive.url]))
    assert "400 MiB" in err


def test_a_dribbling_server_ends_at_the_deadline(archive, config, capsys):
    """A server sending its answer a byte every 0.5 s with timeout = 3 and deadline = 2: one line within the
    deadline and one wait for a byte (before: 121 s with timeout = 3)."""
    name = config(archive.url, timeout=3, deadline=2)
    archive.reply = Reply(endless(b" "), pause=0.5)
    t0 = time.perf_counter()
    err = _one_line(capsys, main(["pacs", "find", name]))
    seconds = time.perf_counter() - t0
    print(f"dribbling server: {err} ({seconds:.1f} s)")
    assert "within 2 s" in err and seconds < 2 + 3 + 2


def test_a_redirect_to_another_host_is_refused(archive, capsys):
    """A 302 to another host: one line naming it, and that host is never asked; a redirect on the same host is
    followed."""
    with HostileArchive() as other:
        other.reply = Reply(json.dumps([dataset_json(PatientName="Other^Host", StudyInstanceUID=UID)]).encode())
        target = other.url.replace("127.0.0.1", "localhost")
        archive.reply = Reply(b"", status=302, headers={"Location": f"{target}/studies"})
        err = _one_line(capsys, main(["pacs", "find", archive.url]))
        assert "redirected the request to another host (localhost)" in err and not other.paths

    def same_host(path):
        if path.startswith("/dicom-web/"):
            return Reply(b"", status=302, headers={"Location": "/moved" + path})
        return Reply(json.dumps([dataset_json(PatientName="Moved^Ok", StudyInstanceUID=UID)]).encode())

    archive.reply = same_host
    assert main(["pacs", "find", archive.url]) == 0
    assert "Moved^Ok" in capsys.readouterr().out


@pytest.mark.parametrize("url", ["http://user:secret@127.0.0.1:9/dicom-web", "http://user@127.0.0.1:9/dicom-web",
                                 "HTTP://user:secret@127.0.0.1:9/x", "http://user:@127.0.0.1:9/x",
                                 "https://a%40b:pw@127.0.0.1:9/x"])
def test_credentials_in_a_url_are_refused(url, capsys):
    """A ``user:password@`` (or just ``user@``) in a URL given as a server: refused in one line that does not
    repeat the password, before any connection."""
    with pytest.raises(ArchiveConfigError):
        resolve_server(url)
    err = _one_line(capsys, main(["pacs", "find", url]))
    assert "secret" not in err and "credentials" in err


def test_credentials_in_a_configured_url_are_refused(config, capsys):
    name = config("http://user:secret@127.0.0.1:9/dicom-web")
    err = _one_line(capsys, main(["pacs", "echo", name]))
    assert "secret" not in err and "credentials" in err


def test_a_retrieve_answered_busy_is_one_line(archive, config, capsys):
    """An instance asked for and answered 503 twice (dicomweb-client retries): one line, exit 1."""
    listed = Reply(json.dumps([dataset_json(SOPInstanceUID="1.2.3.4.5")]).encode())
    archive.reply = lambda path: listed if path.split("?")[0].endswith("/instances") else Reply(b"", status=503)
    err = _one_line(capsys, main(["pacs", "get", archive.url, UID, UID + ".1", "--no-progress"]))
    assert "HTTP 503" in err


def test_a_redirect_with_an_endless_body_is_read_to_the_cap_only(archive, capsys):
    """A 302 on the same host whose body never ends: refused at the cap like any answer (requests reads a
    redirect's body before following it; the cap reads it first)."""
    archive.reply = Reply(endless(b"x" * 4096, b""), status=302, headers={"Location": "/elsewhere"})
    err = _one_line(capsys, main(["pacs", "find", archive.url]))
    assert "more than 64 MiB" in err
