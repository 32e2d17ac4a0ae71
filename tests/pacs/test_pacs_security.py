"""TLS and tokens for DICOMweb, against a small DICOMweb stand-in on a free local port (Python's http.server,
answering QIDO-RS with an empty list): over HTTPS with a self-signed certificate the search works when the
certificate's authority is trusted through ``ca_bundle`` and fails in one typed line without it; a bearer
token reaches the server and no repr, dict or error.

(Not against Orthanc: Debian's Orthanc 1.10.1 dies with SIGSEGV on its first HTTPS request, with or without
plugins.)"""

from __future__ import annotations

import http.server
import json
import shutil
import ssl
import subprocess
import threading
from contextlib import contextmanager

import pytest

import volumen.pacs as pacs
from volumen.errors import ArchiveAuthError, ArchiveUnreachableError

TOKEN = "good-token-123"


class _StandIn(http.server.BaseHTTPRequestHandler):
    """QIDO-RS: ``[]`` to a request bearing TOKEN (or any request when ``open_to_all``), else 401."""

    seen: list = []
    open_to_all = False

    def do_GET(self):
        auth = self.headers.get("Authorization")
        type(self).seen.append((self.path, auth))
        ok = self.open_to_all or auth == f"Bearer {TOKEN}"
        body = b"[]" if ok else b"{}"
        self.send_response(200 if ok else 401)
        self.send_header("Content-Type", "application/dicom+json")
        self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        self.wfile.write(body)

    def log_message(self, *args):
        pass


@contextmanager
def _serving(handler, tls: tuple | None = None):
    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    if tls is not None:
        context = ssl.SSLContext(ssl.PROTOCOL_TLS_SERVER)
        context.load_cert_chain(*tls)
        httpd.socket = context.wrap_socket(httpd.socket, server_side=True)
    thread = threading.Thread(target=httpd.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"{'https' if tls else 'http'}://127.0.0.1:{httpd.server_address[1]}/dicom-web"
    finally:
        httpd.shutdown()
        httpd.server_close()
        thread.join(10)


@pytest.fixture(scope="module")
def certificate(tmp_path_factory):
    if shutil.which("openssl") is None:
        pytest.skip("openssl is not installed (Debian package openssl): no test certificate")
    folder = tmp_path_factory.mktemp("tls")
    key, cert = folder / "key.pem", folder / "cert.pem"
    subprocess.run(["openssl", "req", "-x509", "-newkey", "rsa:2048", "-nodes", "-days", "2", "-subj", "/CN=127.0.0.1",
                    "-addext", "subjectAltName=IP:127.0.0.1", "-keyout", str(key), "-out", str(cert)],
                   check=True, capture_output=True)
    return cert, key


def test_https_with_the_authority_trusted_and_without(certificate, monkeypatch):
    cert, key = certificate
    monkeypatch.setattr(_StandIn, "open_to_all", True)
    with _serving(_StandIn, tls=(str(cert), str(key))) as url:
        assert url.startswith("https://")
        trusted = pacs.Server(name="tls", url=url, ca_bundle=str(cert))
        assert pacs.find(trusted, patient_name="Doe*") == []
        assert _StandIn.seen[-1][0].startswith("/dicom-web/studies?PatientName=Doe*&")
        with pytest.raises(ArchiveUnreachableError, match="TLS handshake failed") as info:
            pacs.find(pacs.Server(name="tls", url=url), patient_name="Doe*")  # the system's authorities only
        assert str(info.value).count("\n") == 0 and "server tls (https://127.0.0.1:" in str(info.value)


def test_bearer_token_reaches_the_server_and_nothing_else(monkeypatch):
    with _serving(_StandIn) as url:
        server = pacs.Server(name="tokens", url=url, token_env="ARCHIVE_TOKEN")
        monkeypatch.setenv("ARCHIVE_TOKEN", TOKEN)
        assert pacs.find(server, patient_name="X*") == []
        assert _StandIn.seen[-1][1] == f"Bearer {TOKEN}"
        assert TOKEN not in repr(server) + json.dumps(server.to_dict())
        monkeypatch.setenv("ARCHIVE_TOKEN", "stale-token-456")
        with pytest.raises(ArchiveAuthError) as info:
            pacs.echo(server)
        assert "HTTP 401" in str(info.value) and "stale-token-456" not in str(info.value)
        monkeypatch.delenv("ARCHIVE_TOKEN")
        with pytest.raises(pacs._config.ArchiveConfigError, match="ARCHIVE_TOKEN .* is not set"):
            pacs.echo(server)
