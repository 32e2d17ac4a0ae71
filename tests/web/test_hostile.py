"""Malformed and hostile requests to the viewer's server: every malformed body is a 400 in one plain line, a
malformed request line a 400 that logs neither the token nor a traceback, a foreign ``Host`` or ``Origin`` a 403,
and the cookie holds a value derived from the token and the port, not the token."""

from __future__ import annotations

import gzip
import http.client
import json
import logging
import socket

import pytest
from test_security import request

from tests.web.web_helpers import reference_scenes, start_server
from volumen.web._requests import BadRequest, frame_request, host_allowed, origin_allowed


@pytest.fixture(scope="module")
def server():
    vol = reference_scenes.volumes()["head"][0]
    scene, cam, _ = reference_scenes.scenes()["head/composite/headlight"]
    srv = start_server(vol, scene, cam)
    yield srv
    srv.stop()


MALFORMED_BODIES = {"null": b"null", "list": b"[]", "one": b"1", "string": b'"x"', "nested": b"[" * 5000,
                    "nested-object": b'{"scene": ' + b"[" * 5000 + b"]" * 5000 + b"}", "not-json": b"{",
                    "not-utf8": b'{"scene": "\xff"}', "empty": b""}


def _good(server) -> dict:
    _, _, info = request(server.port, "GET", "/info.json", headers={"X-Volumen-Token": server.token})
    info = json.loads(info)
    return {"scene": info["scene"], "camera": info["camera"], "size": [8, 8]}


def _bad_values(good: dict) -> dict[str, bytes]:
    out = {}
    for name, text in (("size-inf", '{"scene": %s, "camera": %s, "size": [Infinity, 8]}'),
                       ("size-nan", '{"scene": %s, "camera": %s, "size": [NaN, 8]}'),
                       ("size-big", '{"scene": %s, "camera": %s, "size": [1e999, 8]}'),
                       ("size-neg", '{"scene": %s, "camera": %s, "size": [-1, 8]}'),
                       ("size-str", '{"scene": %s, "camera": %s, "size": ["8", 8]}'),
                       ("max3d-inf", '{"scene": %s, "camera": %s, "size": [8, 8], "max3d": Infinity}'),
                       ("max3d-float", '{"scene": %s, "camera": %s, "size": [8, 8], "max3d": 1.5}'),
                       ("scene-list", '{"scene": [], "camera": %s, "size": [8, 8]}%s'),
                       ("camera-null", '{"scene": %s, "camera": null, "size": [8, 8]}%s'),
                       ("unknown-key", '{"scene": %s, "camera": %s, "size": [8, 8], "x": 1}')):
        args = (json.dumps(good["scene"]), json.dumps(good["camera"]))
        if name in ("scene-list", "camera-null"):
            args = (json.dumps(good["camera"] if name == "scene-list" else good["scene"]), "")
        out[name] = (text % args).encode()
    scene = dict(good["scene"])
    out["scene-lights-string"] = json.dumps({**good, "scene": {**scene, "lights": "x"}}).encode()
    out["scene-shading-list"] = json.dumps({**good, "scene": {**scene, "shading": [1]}}).encode()
    out["camera-fov-string"] = json.dumps({**good, "camera": {**good["camera"], "fov": "wide"}}).encode()
    return out


def test_malformed_frame_bodies_are_400_in_one_line(server, caplog):
    """``null``, ``[]``, ``1``, ``"x"``, 5,000 nested ``[``, ``Infinity`` / ``NaN`` / ``1e999`` as a size or max3d,
    wrong types in the scene and camera, an invalid gzip body: each 400 with one short plain line, and nothing in
    the log but one line per request (before: 500 with a traceback)."""
    caplog.set_level(logging.DEBUG)
    good = _good(server)
    auth = {"X-Volumen-Token": server.token}
    bodies = {**MALFORMED_BODIES, **_bad_values(good)}
    for name, body in bodies.items():
        status, _, text = request(server.port, "POST", "/frame.bin", headers=auth, body=body)
        assert status == 400, (name, status, text[:200])
        assert 0 < len(text) <= 300 and b"\n" not in text.strip() and b"Traceback" not in text, (name, text)
    for name, body in (("bad-gzip", b"\x1f\x8bnot gzip at all"), ("gzip-of-null", gzip.compress(b"null"))):
        status, _, text = request(server.port, "POST", "/frame.bin", body=body,
                                  headers={**auth, "Content-Encoding": "gzip"})
        assert status == 400, (name, status, text[:200])
    status, _, _ = request(server.port, "POST", "/frame.bin", headers=auth, body=json.dumps(good).encode())
    assert status == 200
    assert not any(r.exc_info or "Traceback" in r.getMessage() for r in caplog.records)
    print(f"{len(bodies) + 2} malformed bodies: 400 each")


def test_the_schema_refuses_what_it_should_and_passes_a_frame():
    assert frame_request(b'{"scene": {}, "camera": {}, "size": [8, 8], "max3d": 256, "seq": 3}').max3d == 256
    for body in (b'{"scene": {}, "camera": {}, "size": [8, 8, 8]}', b'{"scene": {}, "camera": {}}',
                 b'{"scene": {}, "camera": {}, "size": [true, 8]}', b'{"scene": {"a": ' + b"[" * 20 + b"]" * 20 + b"}"
                 + b', "camera": {}, "size": [8, 8]}', b'{"scene": {}, "camera": {}, "size": [8, 8], "seq": "x"}'):
        with pytest.raises(BadRequest):
            frame_request(body)


MALFORMED_LINES = [b"GET /info .json?token=%s HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n",
                   b"GET /info.json?token=%s HTTP/9.9\r\nHost: 127.0.0.1\r\n\r\n",
                   b"GET /info.json?token=%s HTTP/1.1\nHost: 127.0.0.1\n\n",
                   b"GET /info.json?token=%s\r\n\r\n",
                   b"G\x00T /?token=%s HTTP/1.1\r\n\r\n",
                   b"GET /?token=%s HTTP/1.1\r\nHost: 127.0.0.1\r\nBad Header: x\r\n\r\n",
                   b"GET /?token=%s HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: -1\r\n\r\n",
                   b"GET /?token=%s HTTP/1.1\r\nHost: 127.0.0.1\r\nX: " + b"a" * 20000 + b"\r\n\r\n",
                   b"GET /" + b"a" * 20000 + b"?token=%s HTTP/1.1\r\n\r\n"]


def _raw(port: int, data: bytes) -> bytes:
    s = socket.create_connection(("127.0.0.1", port), timeout=10)
    try:
        s.sendall(data)
        out = b""
        while True:
            chunk = s.recv(65536)
            if not chunk:
                return out
            out += chunk
    except (TimeoutError, ConnectionResetError):
        return out
    finally:
        s.close()


def test_malformed_request_lines_log_no_token(server, caplog):
    """A space in the path, ``HTTP/9.9``, bare line feeds, a NUL in the method, a bad header, a negative length,
    over-long lines, each with the token in the query: a 4xx (or a closed connection) and log lines that hold
    neither the token nor a traceback (before: aiohttp logged the raw line)."""
    caplog.set_level(logging.DEBUG)
    for line in MALFORMED_LINES:
        answer = _raw(server.port, line.replace(b"%s", server.token.encode()))
        status = answer[9:12]
        assert answer == b"" or status.startswith(b"4") or status == b"200", (line[:60], answer[:100])
        assert server.token.encode() not in answer
    text = "\n".join(r.getMessage() for r in caplog.records)
    assert server.token not in text and server.cookie_value not in text and "Traceback" not in text
    assert not any(r.exc_info for r in caplog.records)
    print(f"{len(MALFORMED_LINES)} malformed requests, {len(caplog.records)} log lines, no token")


def test_foreign_host_and_origin_are_refused(server):
    """DNS rebinding: ``Host: evil.example`` with a valid cookie answers 403; an IP address, ``localhost`` and the
    machine's name pass. A frame request from another site's page (``Origin``) answers 403."""
    cookie = {"Cookie": f"{server.cookie}={server.cookie_value}"}
    assert request(server.port, "GET", "/info.json", headers={**cookie, "Host": "evil.example"})[0] == 403
    assert request(server.port, "GET", "/info.json", headers={**cookie, "Host": "evil.example:80"})[0] == 403
    for host in (f"127.0.0.1:{server.port}", f"localhost:{server.port}", "localhost", "[::1]:80"):
        assert request(server.port, "GET", "/info.json", headers={**cookie, "Host": host})[0] == 200, host
    body = json.dumps(_good(server)).encode()
    own = {"Host": f"127.0.0.1:{server.port}", **cookie}
    assert request(server.port, "POST", "/frame.bin", headers={**own, "Origin": "http://evil.example"},
                   body=body)[0] == 403
    assert request(server.port, "POST", "/frame.bin", headers={**own, "Origin": "null"}, body=body)[0] == 403
    assert request(server.port, "POST", "/frame.bin", headers={**own, "Origin": f"http://127.0.0.1:{server.port}"},
                   body=body)[0] == 200
    assert host_allowed("10.0.0.7:8080", ()) and host_allowed("Viewer.Example.", {"viewer.example"})
    assert not host_allowed("evil.example", {"viewer.example"}) and not host_allowed("[::1", ())
    assert not origin_allowed("https://127.0.0.1:1", "127.0.0.1:1", "http")


def test_the_cookie_is_derived_from_the_token_and_the_port(server):
    """The cookie set by the first answer holds an HMAC of the port by the token: the token itself as the cookie
    is refused, and the value is another server's no more."""
    status, headers, _ = request(server.port, "GET", f"/?token={server.token}")
    assert status == 200 and server.token not in headers["Set-Cookie"]
    assert request(server.port, "GET", "/info.json", headers={"Cookie": f"{server.cookie}={server.token}"})[0] == 403
    vol = reference_scenes.volumes()["head"][0]
    scene, cam, _ = reference_scenes.scenes()["head/composite/headlight"]
    other = start_server(vol, scene, cam, token=server.token)
    try:
        assert other.cookie_value != server.cookie_value
        assert request(other.port, "GET", "/info.json",
                       headers={"Cookie": f"{other.cookie}={server.cookie_value}"})[0] == 403
    finally:
        other.stop()


def test_a_body_past_the_limit_and_unknown_methods(server):
    conn = http.client.HTTPConnection("127.0.0.1", server.port, timeout=30)
    conn.request("PUT", "/frame.bin", body=b"{}", headers={"X-Volumen-Token": server.token})
    assert conn.getresponse().status == 405
    conn.close()


def test_the_certificates_names_are_read_for_the_host_allow_list(tmp_path):
    """``--certfile``: the DNS names of the certificate's Subject Alternative Name join the allowed hosts."""
    import shutil
    import subprocess

    from volumen.web._certificate import certificate_names

    if shutil.which("openssl") is None:
        pytest.skip("openssl is not installed (Debian package openssl): no test certificate")
    subprocess.run(["openssl", "req", "-x509", "-newkey", "rsa:2048", "-nodes", "-days", "2", "-subj", "/CN=viewer",
                    "-keyout", str(tmp_path / "key.pem"), "-out", str(tmp_path / "cert.pem"), "-addext",
                    "subjectAltName=DNS:viewer.example,DNS:ward.local,IP:10.0.0.5"], check=True, capture_output=True)
    names = certificate_names(tmp_path / "cert.pem")
    assert names == ("viewer.example", "ward.local")
    assert host_allowed("viewer.example:8765", names) and not host_allowed("evil.example", names)
    assert certificate_names(tmp_path / "missing.pem") == ()
