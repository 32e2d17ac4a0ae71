"""A hostile DICOMweb archive on a free local port: it answers every request with the reply it is given.

A :class:`Reply` is what the archive sends: a status, headers and a body, the body sent whole, in pieces with
a pause between them (a server dribbling its answer), or generated without end (an answer of any size). The
fuzz campaign (:mod:`._campaign`) and the archive client's tests set :attr:`HostileArchive.reply` before each
request of the client.
"""

from __future__ import annotations

import http.server
import socketserver
import threading
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field

__all__ = ["Reply", "HostileArchive", "dataset_json", "endless"]


@dataclass
class Reply:
    """One answer of the archive.

    Parameters
    ----------
    body : bytes or callable
        The body, or a function returning an iterable of pieces (sent as they come; no ``Content-Length``
        unless ``headers`` say one).
    status : int
    headers : dict
        Sent as given (``Content-Type`` defaults to ``application/dicom+json``).
    pause : float, s
        Between two pieces of the body.
    """

    body: bytes | Callable[[], Iterable[bytes]] = b"[]"
    status: int = 200
    headers: dict = field(default_factory=dict)
    pause: float = 0.0

    def pieces(self) -> Iterable[bytes]:
        return self.body() if callable(self.body) else [self.body]


def dataset_json(**values: str) -> dict:
    """A QIDO-RS study result of the given keywords (``PatientName``, ``PatientID``, ``StudyInstanceUID``...)."""
    from pydicom.datadict import dictionary_VR, tag_for_keyword

    out = {}
    for key, value in values.items():
        tag, vr = tag_for_keyword(key), dictionary_VR(key)
        out[f"{tag:08X}"] = {"vr": vr, "Value": [{"Alphabetic": value} if vr == "PN" else value]}
    return out


def endless(piece: bytes, first: bytes = b"[") -> Callable[[], Iterable[bytes]]:
    """A body that starts with ``first`` and repeats ``piece`` for ever."""
    def gen():
        yield first
        while True:
            yield piece
    return gen


class _Handler(http.server.BaseHTTPRequestHandler):
    protocol_version = "HTTP/1.1"
    archive: HostileArchive

    def _answer(self):
        length = int(self.headers.get("Content-Length") or 0)
        if length:
            self.rfile.read(min(length, 1 << 24))
        reply = self.archive.next_reply(self.path)
        self.send_response(reply.status)
        headers = {"Content-Type": "application/dicom+json", **reply.headers}
        whole = None if callable(reply.body) else reply.body
        if whole is not None and "Content-Length" not in headers:
            headers["Content-Length"] = str(len(whole))
        if "Content-Length" not in headers:
            headers["Connection"] = "close"
        for k, v in headers.items():
            self.send_header(k, v)
        self.end_headers()
        try:
            for piece in reply.pieces():
                self.wfile.write(piece)
                self.wfile.flush()
                if reply.pause:
                    time.sleep(reply.pause)
                if self.archive.stopping:
                    break
        except OSError:   # the client hung up (a cap or a deadline): as it should
            self.close_connection = True
        if "Content-Length" not in headers:
            self.close_connection = True

    do_GET = do_POST = _answer

    def log_message(self, *args):
        pass


class _Server(socketserver.ThreadingMixIn, http.server.HTTPServer):
    daemon_threads = True
    allow_reuse_address = True

    def handle_error(self, request, client_address):
        """A client that hung up mid-answer is what the archive expects: no report."""


class HostileArchive:
    """The archive: ``with HostileArchive() as archive: archive.reply = Reply(...)``; :attr:`url` is its
    DICOMweb root; :attr:`paths` the request paths it was asked."""

    def __init__(self):
        handler = type("Handler", (_Handler,), {"archive": self})
        self._server = _Server(("127.0.0.1", 0), handler)
        self.port = self._server.server_address[1]
        self.url = f"http://127.0.0.1:{self.port}/dicom-web"
        self.reply: Reply | Callable[[str], Reply] = Reply()
        self.paths: list[str] = []
        self.stopping = False
        self._thread = threading.Thread(target=self._server.serve_forever, daemon=True, name="hostile-archive")

    def next_reply(self, path: str) -> Reply:
        self.paths.append(path)
        return self.reply(path) if callable(self.reply) else self.reply

    def __enter__(self) -> HostileArchive:
        self._thread.start()
        return self

    def __exit__(self, *exc):
        self.stopping = True
        self._server.shutdown()
        self._server.server_close()
