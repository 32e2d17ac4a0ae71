"""The viewer's server keeps a patient's scan to whoever holds the token: 403 without it on every route, 404
for anything outside its fixed routes (``..``, encoded ``..``, absolute paths), no patient name, ID or birth
date in anything served or logged (a DICOM series with them set, in a folder named after the patient), the
token printed once as the first line, a warning for a non-loopback host. No browser needed."""

from __future__ import annotations

import http.client
import json
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from tests.io.dicom_factory import PATIENT, write_series
from volumen.web._server import ROUTES

TRAVERSALS = ["/../etc/passwd", "/static/../../etc/passwd", "/static/%2e%2e/%2e%2e/etc/passwd",
              "/%2E%2E/%2E%2E/etc/passwd", "/static/..%2f..%2fetc%2fpasswd", "/static/%252e%252e/etc/passwd",
              "//etc/passwd", "/etc/passwd", "/static//etc/passwd", "/static/..\\..\\etc\\passwd",
              "/static/./main.js/..", "/./info.json/../../etc/passwd", "/static/main.js%00.png", "/index.html",
              "/static/", "/static", "/tmp", "/proc/self/environ", "/usr/lib/python3/os.py"]


def request(port, method, path, *, headers=None, body=None):
    """``(status, headers, body)`` of one request sent with ``path`` exactly as given (no normalization)."""
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=60)
    try:
        c.putrequest(method, path, skip_accept_encoding=True, skip_host="Host" in (headers or {}))
        for k, v in (headers or {}).items():
            c.putheader(k, v)
        if body is not None:
            c.putheader("Content-Length", str(len(body)))
        c.endheaders(body)
        r = c.getresponse()
        return r.status, dict(r.getheaders()), r.read()
    finally:
        c.close()


def _route_paths(info=None):
    out = []
    for route, (method, _) in ROUTES.items():
        path = "/" + route
        body = None
        if route == "frame.bin":
            body = json.dumps({"scene": (info or {}).get("scene", {}), "camera": (info or {}).get("camera", {}),
                               "size": [16, 16]}).encode()
        if route == "slice.png":
            c = (info or {}).get("volume", {}).get("center", [0, 0, 0])
            path += f"?plane=axial&x={c[0]}&y={c[1]}&z={c[2]}&level=40&width=400"
        if route == "region.json":  # a disc of 10 mm about the centre on the axial plane there
            c = (info or {}).get("volume", {}).get("center", [0, 0, 0])
            body = json.dumps({"plane": {"origin": c, "u": [1, 0, 0], "v": [0, 1, 0]},
                               "shape": {"kind": "ellipse", "center": [0, 0], "radii": [10, 10]}}).encode()
        if route == "pick.json":  # the centre of a 16 x 16 picture
            frame = {"scene": (info or {}).get("scene", {}), "camera": (info or {}).get("camera", {}), "size": [16, 16]}
            body = json.dumps({"frame": frame, "x": 8.5, "y": 8.5}).encode()
        out.append((method, path, body))
    return out


def test_every_route_needs_the_token(head_server):
    """No token, a wrong token (same length, one digit off, in the query, header or cookie), another server's
    cookie name: 403 on every route and on unknown paths. The right token in the query, the header or the
    cookie the first answer sets (HttpOnly, SameSite=Strict): 200."""
    port, token = head_server.port, head_server.token
    wrong = token[:-1] + ("0" if token[-1] != "0" else "1")
    denied = [{}, {"X-Volumen-Token": wrong}, {"Cookie": f"{head_server.cookie}={wrong}"},
              {"Cookie": f"volumen-token-1={token}"}, {"X-Volumen-Token": ""}, {"X-Volumen-Token": token[:16]}]
    for method, path, body in _route_paths() + [("GET", p, None) for p in TRAVERSALS]:
        for headers in denied:
            status, _, _ = request(port, method, path, headers=headers, body=body)
            assert status == 403, (method, path, headers)
        sep = "&" if "?" in path else "?"
        assert request(port, method, f"{path}{sep}token={wrong}", body=body)[0] == 403, path
    status, headers, _ = request(port, "GET", f"/?token={token}")
    assert status == 200
    cookie = headers["Set-Cookie"]
    assert cookie.startswith(f"{head_server.cookie}={head_server.cookie_value};") and token not in cookie
    assert "HttpOnly" in cookie and "SameSite=Strict" in cookie
    _, _, info = request(port, "GET", "/info.json", headers={"X-Volumen-Token": token})
    info = json.loads(info)
    for method, path, body in _route_paths(info):
        cookie = f"{head_server.cookie}={head_server.cookie_value}"
        status, _, data = request(port, method, path, headers={"Cookie": cookie}, body=body)
        assert status == 200 and data, (method, path, data[:200])


def test_traversal_and_absolute_paths_are_404(head_server):
    """With the token: ``..`` (plain, percent-encoded, double-encoded, backslashes), absolute paths and any
    name not in the fixed routes answer 404 (nothing is looked up on disk); a route asked with the wrong method
    answers 405; a bad frame request 400 in one line; a body past 1 MiB 413."""
    port, token = head_server.port, head_server.token
    auth = {"X-Volumen-Token": token}
    for path in TRAVERSALS:
        status, _, body = request(port, "GET", path, headers=auth)
        assert status == 404 and b"root:" not in body, (path, status)
    assert request(port, "POST", "/info.json", headers=auth, body=b"{}")[0] == 405
    status, _, body = request(port, "POST", "/frame.bin", headers=auth, body=b'{"scene": {"mode": "nope"}, '
                              b'"camera": {"position": [0, 0, 1]}, "size": [8, 8]}')
    assert status == 400 and b"Scene.mode must be one of" in body and b"\n" not in body.strip()
    assert request(port, "POST", "/frame.bin", headers=auth, body=b"x" * (2 << 20))[0] == 413
    assert request(port, "GET", "/slice.png?plane=../../etc&x=0&y=0&z=0&level=1&width=1", headers=auth)[0] == 400


@pytest.fixture(scope="module")
def patient_series(tmp_path_factory):
    """A DICOM CT series with the patient's name, ID, birth date (and address...) set, in a folder named after
    the patient."""
    folder = tmp_path_factory.mktemp("dicom") / "Doe^Jane_SECRET123_19700101"
    z, y, x = np.mgrid[0:12, 0:24, 0:20]
    raw = (1000 * (((x - 10) ** 2 + (y - 12) ** 2 + (z - 6) ** 2) < 36) - 1000 + 24).astype(np.int16)
    positions = np.array([[0.0, 0.0, 2.5 * k] for k in range(raw.shape[0])])
    write_series(folder, raw, row_dir=(1, 0, 0), col_dir=(0, 1, 0), positions=positions, patient=PATIENT,
                 intercept=-24.0)
    return folder


def _text_of(data: bytes) -> bytes:
    """Everything of a response that could hold text: a binary frame's JSON header (its arrays are numbers), a
    PNG's chunks other than the picture's (none are allowed), anything else whole."""
    from volumen.web import decode

    if data.startswith(b"VOLW"):
        header, _ = decode(data)
        return json.dumps(header).encode()
    if data.startswith(b"\x89PNG"):
        chunks, i = [], 8
        while i < len(data):
            n = int.from_bytes(data[i:i + 4], "big")
            chunks.append(data[i + 4:i + 8])
            i += n + 12
        assert set(chunks) <= {b"IHDR", b"IDAT", b"IEND"}, chunks   # no text chunks
        return b""
    return data


def _serve(args, timeout=120):
    """Start ``volumen serve`` in a fresh process; return it and its first stdout line."""
    proc = subprocess.Popen([sys.executable, "-m", "volumen", "serve", *args, "--no-browser"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    end = time.monotonic() + timeout
    line = proc.stdout.readline()
    assert time.monotonic() < end and line, proc.stderr.read() if proc.poll() is not None else "no URL"
    return proc, line.strip()


def _stop(proc) -> tuple[str, str]:
    proc.send_signal(signal.SIGINT)
    try:
        out, err = proc.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        proc.kill()
        out, err = proc.communicate()
    return out, err


def test_patient_identity_is_neither_served_nor_logged(patient_series):
    """``volumen serve`` on a DICOM series with PatientName, PatientID, PatientBirthDate (and address,
    physician, institution, accession number) set: the page, its modules and shaders, info.json, the volume,
    a frame and the three slice pictures hold none of them, nor the folder's name; neither do stdout and
    stderr (the request log). The token is 128 random bits, printed once: the first line, alone."""
    proc, url = _serve([str(patient_series), "--port", "0"])
    try:
        m = re.fullmatch(r"http://127\.0\.0\.1:(\d+)/\?token=([0-9a-f]{32})", url)
        assert m, url
        port, token = int(m.group(1)), m.group(2)
        auth = {"X-Volumen-Token": token}
        status, _, info = request(port, "GET", "/info.json", headers=auth)
        assert status == 200
        info = json.loads(info)
        assert info["volume"]["modality"] == "CT" and info["scene"]["volume"] == ""
        c = info["volume"]["center"]
        asked = _route_paths(info) + [("GET", f"/slice.png?plane={p}&x={c[0]}&y={c[1]}&z={c[2]}&level=40&width=400",
                                       None) for p in ("coronal", "sagittal")]
        served = []
        for method, path, body in asked:
            status, headers, data = request(port, method, path, headers=auth, body=body)
            assert status == 200, (path, data[:300])
            served += [_text_of(data), json.dumps(headers).encode()]
    finally:
        out, err = _stop(proc)
    secrets = [*PATIENT.values(), "Doe", "Jane", "1970-01-01", str(patient_series)]
    blob = b"\n".join(served).decode("utf-8", "replace")
    logs = url + "\n" + out + err
    for s in secrets:   # as words, any case ("doe" is in "does")
        word = re.compile(rf"(?<![A-Za-z0-9]){re.escape(s)}(?![A-Za-z0-9])", re.IGNORECASE)
        assert not word.search(blob), f"{s!r} served"
        assert not word.search(logs), f"{s!r} logged"
    assert out.strip() == "" and token not in err and "GET info.json 200" in err  # the URL once; logged, no token
    assert len(token) * 4 == 128


def test_non_loopback_host_prints_one_warning_line(monkeypatch, capsys):
    """``--host 0.0.0.0``: the URL is the first line on stdout, then one line on stderr says the scan is
    reachable from the network; the loopback default says nothing of the kind (the server is stopped at once)."""
    from volumen.cli import main
    from volumen.web import ViewerServer

    monkeypatch.setattr(ViewerServer, "run", lambda self: self.sock.close())
    for host in ("0.0.0.0", "127.0.0.1"):
        assert main(["serve", "phantom:sphere?size=16", "--host", host, "--port", "0", "--no-browser"]) == 0
        out, err = capsys.readouterr()
        assert re.fullmatch(r"https?://\S+:\d+/\?token=[0-9a-f]{32}\n", out), out
        if host == "0.0.0.0":
            assert err.startswith("volumen serve: warning: listening on 0.0.0.0") and "network" in err
            assert err.count("\n") == 1
        else:
            assert out.startswith("http://127.0.0.1:") and "warning" not in err


def test_the_page_is_the_files_of_its_folder(monkeypatch, tmp_path):
    """The page's files are found in its folder, not listed by hand: a file added to the folder is served (its bytes,
    its content type), while a file beside the folder, one in a folder inside it and one of another type are 404."""
    import shutil

    from tests.web.web_helpers import start_server
    from volumen.data import phantom
    from volumen.web import _handlers

    folder = tmp_path / "static"
    shutil.copytree(Path(_handlers.static_folder()), folder)
    (folder / "added.js").write_text("export const added = 1;\n")
    (folder / "notes.txt").write_text("not a page file\n")
    (folder / "inner").mkdir()
    (folder / "inner" / "deep.js").write_text("export const deep = 1;\n")
    (tmp_path / "outside.js").write_text("export const outside = 1;\n")
    monkeypatch.setattr(_handlers, "static_folder", lambda: folder)
    assert set(_handlers.static_files()) == set(_handlers.STATIC_FILES) | {"added.js"}
    vol = phantom("sphere", size=16)
    from volumen.core import Camera, Scene

    srv = start_server(vol, Scene(volume=vol), Camera.orbit(vol))
    try:
        auth = {"X-Volumen-Token": srv.token}
        status, headers, body = request(srv.port, "GET", "/static/added.js", headers=auth)
        assert (status, body) == (200, b"export const added = 1;\n")
        assert headers["Content-Type"].startswith("text/javascript")
        assert request(srv.port, "GET", "/static/main.js", headers=auth)[0] == 200
        for path in ("/static/notes.txt", "/static/inner/deep.js", "/static/../outside.js", "/outside.js",
                     "/static/outside.js", "/static/inner"):
            assert request(srv.port, "GET", path, headers=auth)[0] == 404, path
    finally:
        srv.stop()
