"""TLS and tokens for DICOMweb. HTTPS with a self-signed certificate, in front of the test Orthanc: searching and
retrieving with the user's password work when the certificate's authority is trusted through ``ca_bundle`` and
fail in one typed line without it. A bearer token, against a small DICOMweb stand-in on a free local port
(Python's http.server, answering QIDO-RS with an empty list; Orthanc has no tokens without an authorization
plugin), reaches the server and no repr, dict or error.

TLS ends in a relay of this module (https on a free port -> Orthanc's http port), as in a deployment behind a
reverse proxy, because Debian 12's Orthanc 1.10.1 cannot serve HTTPS itself: its civetweb (libcivetweb1 1.15)
loads OpenSSL at run time with the OpenSSL 1.1 symbol table, finds no ``SSL_get_peer_certificate`` in
OpenSSL 3 and calls a null pointer on the first TLS connection (SIGSEGV in a civetweb worker, whatever the
Ssl* settings)."""

from __future__ import annotations

import http.server
import json
import selectors
import shutil
import socket
import socketserver
import ssl
import subprocess
import threading
from contextlib import contextmanager

import numpy as np
import pytest

import volumen
import volumen.pacs as pacs
from volumen.errors import ArchiveAuthError, ArchiveUnreachableError

TOKEN = "good-token-123"


class _StandIn(http.server.BaseHTTPRequestHandler):
    """QIDO-RS: ``[]`` to a request bearing TOKEN, else 401."""

    seen: list = []

    def do_GET(self):
        auth = self.headers.get("Authorization")
        type(self).seen.append((self.path, auth))
        ok = auth == f"Bearer {TOKEN}"
        body = b"[]" if ok else b"{}"
        self.send_response(200 if ok else 401)
        self.send_header("Content-Type", "application/dicom+json")
        self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        self.wfile.write(body)

    def log_message(self, *args):
        pass


@contextmanager
def _running(server):
    """``server`` (a socketserver) answering on a thread until the block ends; its port."""
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield server.server_address[1]
    finally:
        server.shutdown()
        server.server_close()
        thread.join(10)


def _relay(tls: ssl.SSLSocket, plain: socket.socket) -> None:
    """Bytes both ways until either side closes (one thread: an SSL socket is not used from two)."""
    with selectors.DefaultSelector() as sel:
        sel.register(tls, selectors.EVENT_READ, plain)
        sel.register(plain, selectors.EVENT_READ, tls)
        while True:
            for key, _ in sel.select(timeout=30):
                source, target = key.fileobj, key.data
                data = source.recv(65536)
                while isinstance(source, ssl.SSLSocket) and source.pending():
                    data += source.recv(65536)
                if not data:
                    return
                target.sendall(data)


def _tls_in_front(http_port: int, cert, key):
    """A TLS-ending relay to ``http_port`` (a socketserver to run with :func:`_running`)."""
    context = ssl.SSLContext(ssl.PROTOCOL_TLS_SERVER)
    context.load_cert_chain(cert, key)

    class Relay(socketserver.BaseRequestHandler):
        def handle(self):
            try:
                tls = context.wrap_socket(self.request, server_side=True)
            except (ssl.SSLError, OSError):
                return  # a client that does not trust the certificate
            with tls, socket.create_connection(("127.0.0.1", http_port)) as plain:
                _relay(tls, plain)

    server = socketserver.ThreadingTCPServer(("127.0.0.1", 0), Relay)
    server.daemon_threads = True
    return server


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


def test_https_with_the_authority_trusted_and_without(certificate, archive, archive_config, tmp_path, monkeypatch):
    """``ca_bundle`` is trusted by the search and by dicomweb-client's retrieve, even where REQUESTS_CA_BUNDLE (which
    requests lets override a session's verify) names the system's authorities; without ca_bundle, the
    environment's bundle decides for both."""
    import certifi

    cert, key = certificate
    monkeypatch.setenv("REQUESTS_CA_BUNDLE", certifi.where())  # authorities that do not include the test's
    with _running(_tls_in_front(archive.server.http_port, str(cert), str(key))) as port:
        url = f"https://127.0.0.1:{port}/dicom-web"
        entry = {**pacs.resolve_server("archive", protocol="dicomweb").to_dict(), "name": "tls", "url": url}
        trusted = pacs.Server.from_dict({**entry, "ca_bundle": str(cert)})
        ct = archive.ct
        assert [s.uid for s in pacs.find(trusted, patient_name="Doe^Jane")] == [ct.study_uid]
        folder = pacs.retrieve(trusted, ct.study_uid, ct.series_uid, cache=tmp_path / "trusted")
        assert np.array_equal(np.asarray(volumen.load(folder).data), np.asarray(volumen.load(ct.folder).data))
        with pytest.raises(ArchiveUnreachableError, match="TLS handshake failed") as info:
            pacs.find(pacs.Server.from_dict(entry), patient_name="Doe*")  # the environment's authorities only
        assert str(info.value).count("\n") == 0 and "server tls (https://127.0.0.1:" in str(info.value)
        monkeypatch.setenv("REQUESTS_CA_BUNDLE", str(cert))  # an authority trusted by the environment
        assert [s.uid for s in pacs.find(pacs.Server.from_dict(entry), patient_id="PAT-001")] == [ct.study_uid]
        assert pacs.retrieve(pacs.Server.from_dict(entry), ct.study_uid, ct.series_uid, cache=tmp_path / "env").is_dir()


def test_bearer_token_reaches_the_server_and_nothing_else(monkeypatch):
    with _running(http.server.ThreadingHTTPServer(("127.0.0.1", 0), _StandIn)) as port:
        url = f"http://127.0.0.1:{port}/dicom-web"
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
