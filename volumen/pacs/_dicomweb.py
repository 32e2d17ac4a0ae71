"""DICOMweb: QIDO-RS (search), WADO-RS (retrieve, one instance per request) and STOW-RS with ``dicomweb-client``.

Searches are GET requests written here rather than by ``dicomweb-client``, for one reason: the query string.
The client percent-encodes every matching value (``Doe%2A``, ``Doe%5EJane``), which the standard allows but
Orthanc 1.10 (Debian 12) does not decode (it matches the literal ``%2A``). Here the wildcards ``*`` and
``?``, legal in a query as they are, travel unescaped and everything else is percent-encoded, so a wildcard
search finds the same studies on Orthanc as on servers that decode. What must travel escaped (the name
separator ``^``, a space, non-ASCII letters: urllib3 escapes them whatever the caller sends) cannot match
there, so a study search with such a value that finds nothing is asked again with the wildcard ``?`` in
place of each escaped character, and only the studies whose values match the value asked for are kept
(:func:`loosened`, :func:`matches`): ``Doe^Jane`` finds Doe^Jane on Orthanc 1.10, and a server that decodes
pays one more request only when there is nothing to find.

Instances are fetched one request each, in the order QIDO lists them, so a transfer cut in the middle
loses at most the instance in flight and a rerun asks only for the missing ones. HTTP failures become
the typed errors of :mod:`volumen.errors`, naming the server (its name and URL), never a credential:
the password or token travels in a ``requests`` authentication object, not in the URL or a header that
``dicomweb-client`` logs.
"""

from __future__ import annotations

import re
import struct
import time
import warnings
from collections.abc import Callable, Iterable
from contextlib import contextmanager
from urllib.parse import quote

from ..errors import (
    ArchiveAuthError,
    ArchiveError,
    ArchiveNotFoundError,
    ArchiveRefusedError,
    ArchiveUnreachableError,
)
from ._config import Server
from ._credentials import Prompt, forget, password, token
from ._http import bearer, session
from ._privacy import redact_logs
from ._records import SERIES_KEYS, STUDY_KEYS, Query, Series, Study, printable

__all__ = ["DicomWebArchive", "query_string", "loosened", "matches"]

_RAW = "*?-._~"  # sent unescaped: DICOM's wildcards and RFC 3986's unreserved marks


def query_string(params: dict[str, str | int | list]) -> str:
    """``key=value&...`` with only what must be escaped percent-encoded (see the module's docstring)."""
    parts = []
    for key, value in params.items():
        for v in value if isinstance(value, (list, tuple)) else (value,):
            parts.append(f"{quote(str(key), safe='')}={quote(str(v), safe=_RAW)}")
    return "&".join(parts)


def loosened(filters: dict[str, str]) -> dict[str, str]:
    """The matching values that travel percent-encoded, each escaped character replaced by the wildcard ``?``
    (for a server that matches the query text as sent); empty when every value travels as it is."""
    out = {}
    for key, value in filters.items():
        loose = "".join(c if quote(c, safe=_RAW) == c else "?" for c in value)
        if loose != value:
            out[key] = loose
    return out


def matches(ds, filters: dict[str, str]) -> bool:
    """Whether ``ds`` (a QIDO-RS result) has, for each keyword of ``filters``, a value matching it with DICOM's
    wildcards (``*`` any run, ``?`` one character; letters in any case, as for person names)."""
    from pydicom.multival import MultiValue

    for key, pattern in filters.items():
        regex = "".join(".*" if c == "*" else "." if c == "?" else re.escape(c) for c in pattern)
        value = ds.get(key)
        values = list(value) if isinstance(value, MultiValue) else [] if value is None else [value]
        if not any(re.fullmatch(regex, str(v), re.IGNORECASE | re.DOTALL) for v in values):
            return False
    return True


def _reason(exc: Exception) -> str:
    """A short cause for a connection failure (no URL: it is in the server's label already)."""
    import requests

    if isinstance(exc, requests.exceptions.SSLError):
        return "the TLS handshake failed (certificate not trusted? set ca_bundle in servers.toml)"
    if isinstance(exc, requests.exceptions.Timeout):
        return "did not answer in time"
    if isinstance(exc, requests.exceptions.ChunkedEncodingError):
        return "the connection broke in the middle of a transfer"
    text = str(exc)
    for cause in ("Connection refused", "Name or service not known", "Connection reset", "No route to host",
                  "Remote end closed connection", "Connection aborted"):
        if cause in text:
            return f"did not answer ({cause.lower()})"
    return "did not answer (no connection)"


class ReplyShapeError(ValueError):
    """An answer of a shape DICOMweb does not have (``_errors`` names the request and the server)."""


def _is_dataset_json(d) -> bool:
    """Whether ``d`` looks like a DICOM JSON dataset: an object of ``{"vr": ...}`` objects by 8-hex-digit tag."""
    return isinstance(d, dict) and all(isinstance(k, str) and len(k) == 8 and isinstance(v, dict)
                                       and isinstance(v.get("vr"), str) for k, v in d.items())


class DicomWebArchive:
    """One DICOMweb server; ``ask`` prompts for a missing password (None: never ask)."""

    def __init__(self, server: Server, ask: Prompt | None = None):
        import requests
        from dicomweb_client.api import DICOMwebClient

        redact_logs()
        self.server = server
        self.session = session(server)
        secret = token(server)
        if secret:
            self.session.auth = bearer(secret)
        elif server.username is not None:
            self.session.auth = requests.auth.HTTPBasicAuth(server.username, password(server, ask))
        self.timeout = (min(server.timeout, 10.0), server.timeout)
        self.client = DICOMwebClient(url=server.url.rstrip("/"), session=self.session, timeout=self.timeout)
        self.client.set_http_retry_params(max_attempts=2, wait_exponential_multiplier=200)

    def close(self) -> None:
        self.session.close()

    def _search(self, path: str, params: dict) -> list:
        """A QIDO-RS GET of ``path`` (``studies``, ``studies/UID/series``...): the pydicom datasets found."""
        import requests
        from pydicom import Dataset

        url = f"{self.server.url.rstrip('/')}/{path}?{query_string(params)}"
        prepared = self.session.prepare_request(requests.Request("GET", url, headers={
            "Accept": "application/dicom+json"}))
        prepared.url = url  # as written: requests would escape the ^ of a name again
        settings = self.session.merge_environment_settings(url, {}, None, None, None)  # proxies, CA bundle
        response = self.session.send(prepared, timeout=self.timeout, **settings)
        response.raise_for_status()
        found = response.json() if response.content else []
        found = [found] if isinstance(found, dict) else found
        if not isinstance(found, list) or not all(_is_dataset_json(d) for d in found):
            raise ReplyShapeError("the answer is not a list of DICOM JSON datasets")
        with warnings.catch_warnings():  # pydicom's warnings about odd values quote the values
            warnings.simplefilter("ignore")
            try:
                return [Dataset.from_json(d) for d in found]
            except Exception as exc:  # noqa: BLE001 - pydicom's many ways of refusing odd JSON, as one error
                raise ReplyShapeError(f"a dataset in the answer is not DICOM JSON ({type(exc).__name__})") from None

    @contextmanager
    def _errors(self, what: str, missing: str | None = None):
        """Map ``requests`` failures to typed errors: ``what`` is the request in words, ``missing`` what a 404
        means (None: a plain refusal)."""
        import requests
        from pydicom.errors import BytesLengthException, InvalidDicomError
        from retrying import RetryError  # dicomweb-client's retries of 429, 503 and 504

        label = self.server.label
        try:
            yield
        except ArchiveError:
            raise
        except requests.exceptions.HTTPError as exc:
            code = exc.response.status_code if exc.response is not None else 0
            if code in (401, 403):
                forget(self.server)
                who = f"user {self.server.username}" if self.server.username else "requests without credentials"
                raise ArchiveAuthError(label, f"refused {who} (HTTP {code}: wrong user name or password, or no "
                                              "access)") from None
            if code == 404 and missing:
                raise ArchiveNotFoundError(label, missing) from None
            if code == 404:
                raise ArchiveRefusedError(label, f"{what} failed (HTTP 404: is the url the DICOMweb root, e.g. "
                                                 "http://host:8042/dicom-web?)") from None
            reason = printable(exc.response.reason or "")[:80] if exc.response is not None else ""
            raise ArchiveRefusedError(label, f"{what} failed (HTTP {code} {reason})".replace(" )", ")")) from None
        except requests.exceptions.JSONDecodeError:
            raise ArchiveRefusedError(label, f"{what}: the answer is not DICOM JSON (is the url the DICOMweb "
                                             "root?)") from None
        except requests.exceptions.RequestException as exc:
            raise ArchiveUnreachableError(label, _reason(exc)) from None
        except InvalidDicomError:
            raise ArchiveRefusedError(label, f"{what}: the server sent an instance that is not a DICOM Part 10 file "
                                             "(no file meta information)") from None
        except RetryError as exc:
            code = getattr(getattr(exc.last_attempt, "value", None), "status_code", "?")
            raise ArchiveRefusedError(label, f"{what} failed (HTTP {code}, asked twice)") from None
        except ReplyShapeError as exc:
            raise ArchiveRefusedError(label, f"{what}: {exc}") from None
        except (ValueError, TypeError, KeyError, AttributeError, IndexError, RecursionError, OverflowError, EOFError,
                struct.error, BytesLengthException, NotImplementedError) as exc:  # what pydicom makes of its answer
            text = str(exc).splitlines()[0][:120] if str(exc) else type(exc).__name__
            raise ArchiveRefusedError(label, f"{what}: unexpected answer ({printable(text)})") from None

    def echo(self) -> float:
        """Seconds a one-study search took (DICOMweb has no echo of its own)."""
        t0 = time.perf_counter()
        with self._errors("a search"):
            self._search("studies", {"limit": 1})
        return time.perf_counter() - t0

    def find_studies(self, query: Query) -> list[Study]:
        """The studies matching ``query``; asked again with ``?`` for escaped characters when none is found (see
        the module's docstring)."""
        params = {**query.filters(), "includefield": list(STUDY_KEYS)}
        with self._errors("the study search"):
            found = self._search("studies", {**params, "limit": query.limit} if query.limit else params)
            loose = {} if found else loosened(query.filters())
            if loose:
                wanted = {key: query.filters()[key] for key in loose}
                found = [ds for ds in self._search("studies", {**params, **loose}) if matches(ds, wanted)]
            return [Study.from_dataset(ds) for ds in found[: query.limit or None]]

    def find_series(self, study_uid: str) -> list[Series]:
        with self._errors("the series search", f"has no study {study_uid}"):
            found = self._search(f"studies/{study_uid}/series", {"includefield": list(SERIES_KEYS)})
            return [Series.from_dataset(ds, study_uid) for ds in found]

    def list_instances(self, study_uid: str, series_uid: str) -> list[str]:
        with self._errors("the instance search", f"has no series {series_uid} in study {study_uid}"):
            found = self._search(f"studies/{study_uid}/series/{series_uid}/instances",
                                 {"includefield": "SOPInstanceUID"})
            return [str(ds.SOPInstanceUID) for ds in found if "SOPInstanceUID" in ds]

    def fetch(self, study_uid: str, series_uid: str, sop_uids: list[str], sink: Callable, stop: Callable[[], bool]):
        """WADO-RS each instance of ``sop_uids`` in turn into ``sink(dataset)``; returns early when ``stop()``."""
        for uid in sop_uids:
            if stop():
                return
            with self._errors("the retrieve", f"has no instance {uid} (deleted since it was listed?)"), \
                    warnings.catch_warnings():  # pydicom's warnings about odd values quote the values
                warnings.simplefilter("ignore")
                ds = self.client.retrieve_instance(study_uid, series_uid, uid)
                sent = str(ds.get("SOPInstanceUID", ""))
                if sent != uid:
                    raise ArchiveRefusedError(self.server.label, f"sent instance {printable(sent[:64]) or '(none)'} "
                                                                 f"when asked for {uid}")
                sink(ds)

    def store(self, datasets: Iterable) -> int:
        """STOW-RS ``datasets``; the number stored. A refused instance is an error naming its SOP Instance UID."""
        datasets = list(datasets)
        with self._errors("the store"):
            answer = self.client.store_instances(datasets)
            failed = list(answer.get("FailedSOPSequence", [])) if answer is not None else []
            if failed:
                uid = printable(str(failed[0].get("ReferencedSOPInstanceUID", "?")))
                reason = printable(str(failed[0].get("FailureReason", "?")))
        if failed:
            raise ArchiveRefusedError(self.server.label, f"refused {len(failed)} of {len(datasets)} instance(s) "
                                                         f"(first: {uid}, failure reason {reason})")
        return len(datasets)
