"""The HTTP session of a DICOMweb archive: trusted authorities, credentials, and limits on what a server sends.

:func:`session` makes the ``requests`` session that both the searches written here and ``dicomweb-client``
use, so every request of an archive holds to the same rules:

* **a byte cap**: an answer's body is read in pieces as they arrive and abandoned past ``Server.max_answer_mb``
  (searches, stores: a 400 MB search answer is not read whole) or ``Server.max_instance_mb`` (an instance);
* **a deadline**: an answer must arrive whole within ``Server.deadline`` seconds of the request, however
  slowly the server sends it (``timeout`` bounds one wait for a byte; a byte every 2 s never trips it);
* **no redirect to another host**: the archive's answers come from the archive (a redirect to the same
  scheme, host and port is followed);
* **the CA bundle**: a configured ``ca_bundle`` wins over ``REQUESTS_CA_BUNDLE`` / ``CURL_CA_BUNDLE``.

The body is read by a response hook, which ``requests`` runs before it follows a redirect or anyone reads the
body, with ``urllib3``'s ``read1`` (what has arrived, at most a piece), and handed to ``requests`` as the
response's content, which ``dicomweb-client`` reads as if it had been read there.
"""

from __future__ import annotations

import time
from urllib.parse import urljoin, urlsplit

from ..errors import ArchiveRefusedError, ArchiveUnreachableError
from ._config import Server

__all__ = ["session", "bearer", "same_origin"]

_PIECE = 1 << 16


def bearer(value: str):
    """A ``requests`` authentication object sending ``Authorization: Bearer value`` (its repr hides it)."""
    from requests.auth import AuthBase

    class Bearer(AuthBase):
        def __call__(self, request):
            request.headers["Authorization"] = f"Bearer {value}"
            return request

        def __repr__(self):
            return "Bearer(...)"

    return Bearer()


def _origin(url: str) -> tuple[str, str, int | None]:
    parts = urlsplit(url)
    port = parts.port or {"http": 80, "https": 443}.get(parts.scheme.lower())
    return parts.scheme.lower(), (parts.hostname or "").lower(), port


def same_origin(a: str, b: str) -> bool:
    """Whether two URLs have the same scheme, host and port."""
    return _origin(a) == _origin(b)


def _cap(server: Server, request) -> tuple[float, str]:
    """``(MiB, setting)``: the cap on the answer to ``request`` (an instance's, or a search's or a store's)."""
    accept = request.headers.get("Accept", "")
    if request.method == "GET" and "json" not in accept:
        return server.max_instance_mb, "max_instance_mb"
    return server.max_answer_mb, "max_answer_mb"


def _too_big(server: Server, response, mib: float, setting: str, declared: int | None = None):
    response.close()
    size = f"{declared / 2**20:.0f} MiB, more than the {mib:g} MiB allowed" if declared else f"more than {mib:g} MiB"
    return ArchiveRefusedError(server.label, f"sent an answer of {size} ({setting} in servers.toml)")


def _piece(raw, server: Server) -> bytes:
    """What has arrived of a body (at most 64 KiB); urllib3's failures as the archive's errors."""
    from urllib3.exceptions import DecodeError, HTTPError, ReadTimeoutError

    try:
        return raw.read1(_PIECE)
    except ReadTimeoutError:
        raise ArchiveUnreachableError(server.label, "did not answer in time") from None
    except DecodeError:
        raise ArchiveRefusedError(server.label, "sent an answer that does not decode (its content encoding)") from None
    except (HTTPError, OSError):
        raise ArchiveUnreachableError(server.label, "the connection broke in the middle of a transfer") from None


def _read_capped(response, server: Server, end: float) -> bytes:
    """The body of a streamed ``response``: at most its cap (:func:`_cap`), whole before ``end``."""
    mib, setting = _cap(server, response.request)
    cap = int(mib * 2 ** 20)
    declared = response.headers.get("Content-Length", "")
    if declared.isdigit() and int(declared) > cap:
        raise _too_big(server, response, mib, setting, int(declared))
    pieces, size = [], 0
    raw = response.raw
    while True:
        if time.monotonic() > end:
            response.close()
            raise ArchiveUnreachableError(server.label, f"did not send its answer within {server.deadline:g} s "
                                                        "(deadline in servers.toml)")
        piece = _piece(raw, server)
        if not piece:
            return b"".join(pieces)
        size += len(piece)
        if size > cap:
            raise _too_big(server, response, mib, setting)
        pieces.append(piece)


def session(server: Server):
    """A ``requests`` session for ``server`` holding to the module's rules (credentials are set by the caller)."""
    import requests

    class Session(requests.Session):
        def merge_environment_settings(self, url, proxies, stream, verify, cert):
            merged = super().merge_environment_settings(url, proxies, stream, verify, cert)
            if server.ca_bundle:
                merged["verify"] = server.ca_bundle
            return merged

        def get_redirect_target(self, resp):
            target = super().get_redirect_target(resp)
            if target is not None and not same_origin(urljoin(resp.url, target), server.url):
                resp.close()
                where = _origin(urljoin(resp.url, target))[1] or "?"
                raise ArchiveRefusedError(server.label, f"redirected the request to another host ({where}); "
                                                        "refused (set the server's url to it if it is trusted)")
            return target

        def send(self, request, **kwargs):
            kwargs["stream"] = True   # the body is read by the hook below, capped, before anything else reads it
            if not hasattr(request, "volumen_deadline"):
                request.volumen_deadline = time.monotonic() + server.deadline
            return super().send(request, **kwargs)

    def read_body(response, *args, **kwargs):
        """The response hook (run before requests follows a redirect or anyone reads the body)."""
        end = getattr(response.request, "volumen_deadline", time.monotonic() + server.deadline)
        try:
            response._content = _read_capped(response, server, end)
        except BaseException:
            response.close()   # abandoned: the connection is closed
            raise
        response._content_consumed = True
        response.raw.release_conn()   # read whole: the connection goes back to the pool
        return response

    s = Session()
    s.verify = server.ca_bundle or True
    s.max_redirects = 5
    s.hooks["response"].append(read_body)
    return s
