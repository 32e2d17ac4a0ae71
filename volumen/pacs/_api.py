"""The archive functions users call: echo, find, series, retrieve, load, send; ``dicomweb://`` references.

Each takes a server as a name in ``servers.toml``, a DICOMweb URL, ``AE_TITLE@HOST:PORT`` or a
:class:`Server`, and ``protocol="dicomweb"|"dimse"`` to choose when a server speaks both. Retrieval lands
in the cache (:class:`SeriesCache`) and the existing DICOM reader loads it: nothing renders from a socket.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterable
from contextlib import contextmanager
from pathlib import Path

from ..errors import (
    ArchiveConfigError,
    ArchiveNotFoundError,
    ArchiveRefusedError,
    MultipleSeriesError,
    RetrieveCancelled,
)
from ._client import ArchiveClient
from ._config import Server, resolve_server
from ._credentials import Prompt
from ._records import Query, Series, Studies, check_uid
from ._series_cache import SeriesCache

__all__ = ["echo", "find", "series", "retrieve", "load", "send", "parse_ref", "make_ref", "connect", "REF_SCHEMES"]

#: reference scheme -> protocol: ``dicomweb://SERVER/STUDY[/SERIES]`` and ``dimse://SERVER/STUDY[/SERIES]``
REF_SCHEMES = {"dicomweb": "dicomweb", "dimse": "dimse"}

Progress = Callable[[int, int], None]


def _archive_class(kind: str) -> type[ArchiveClient]:
    if kind == "dicomweb":
        from ._dicomweb import DicomWebArchive

        return DicomWebArchive
    from ._dimse import DimseArchive

    return DimseArchive


@contextmanager
def connect(server: str | Server, *, protocol: str | None = None, ask: Prompt | None = None):
    """The protocol client of ``server`` (an :class:`ArchiveClient`: ``DicomWebArchive`` or ``DimseArchive``),
    closed after the block."""
    srv = resolve_server(server, protocol=protocol)
    archive = _archive_class(srv.kind)(srv, ask)
    try:
        yield archive
    finally:
        archive.close()


def echo(server: str | Server, *, protocol: str | None = None, ask: Prompt | None = None) -> float:
    """Seconds the server took to answer a C-ECHO (DIMSE) or a one-study search (DICOMweb)."""
    with connect(server, protocol=protocol, ask=ask) as archive:
        return archive.echo()


def find(server: str | Server, *, protocol: str | None = None, ask: Prompt | None = None, **query) -> Studies:
    """The studies matching ``query`` (the fields of :class:`Query`), by date then UID: a list of
    :class:`Study` that Jupyter shows as a table.

    Examples
    --------
    >>> volumen.pacs.find("archive", patient_name="Doe*", study_date="20240101-20241231", modality="CT")
    """
    q = query.pop("query", None) or Query(**query)
    with connect(server, protocol=protocol, ask=ask) as archive:
        found = archive.find_studies(q)
    return Studies(sorted(found, key=lambda s: (s.date, s.uid)))


def series(server: str | Server, study_uid: str, *, protocol: str | None = None,
           ask: Prompt | None = None) -> list[Series]:
    """The series of a study, by series number."""
    check_uid(study_uid, "study UID")
    with connect(server, protocol=protocol, ask=ask) as archive:
        found = archive.find_series(study_uid)
    if not found:
        raise ArchiveNotFoundError(resolve_server(server, protocol=protocol).label, f"has no study {study_uid}")

    def key(s):
        try:
            return (0, float(s.number), s.uid)
        except ValueError:
            return (1, 0.0, s.uid)

    return sorted(found, key=key)


def retrieve(server: str | Server, study_uid: str, series_uid: str, *, protocol: str | None = None,
             cache: str | Path | None = None, progress: Progress | None = None,
             cancel: threading.Event | Callable[[], bool] | None = None, refresh: bool = False,
             ask: Prompt | None = None) -> Path:
    """Fetch one series into the cache; the folder of its files.

    A series already complete in the cache is not fetched again (``refresh=True`` does). Instances land
    whole in a partial folder that becomes the series' folder only when every one listed is in, so a
    transfer cut in the middle leaves no half series, and a rerun fetches only what is missing.

    Parameters
    ----------
    server : str or Server
    study_uid, series_uid : str
    protocol : {"dicomweb", "dimse"}, optional
    cache : path, optional
        Root of the cache (default ``cache_dir() / "archives"``).
    progress : callable, optional
        ``progress(done, total)`` in instances, after each one.
    cancel : threading.Event or callable, optional
        Checked between instances; when set, :class:`RetrieveCancelled` (what came is kept for a rerun).

    Raises
    ------
    ArchiveError
        (a subclass) naming the server: unreachable, refused credentials, series not found, cancelled.
    """
    srv = resolve_server(server, protocol=protocol)
    where = SeriesCache(srv.name, study_uid, series_uid, None if cache is None else Path(cache))
    if where.complete() and not refresh:
        return where.folder
    stop = cancel.is_set if isinstance(cancel, threading.Event) else (cancel or (lambda: False))
    with connect(srv, ask=ask) as archive:
        listed = archive.list_instances(study_uid, series_uid)
        if not listed:
            raise ArchiveNotFoundError(srv.label, f"has no series {series_uid} in study {study_uid} (deleted since "
                                                  "it was found?)")
        where.keep_only(set(listed))
        have = where.present()
        missing = [uid for uid in listed if uid not in have]
        done = len(have)
        if progress:
            progress(done, len(listed))

        def sink(ds):
            nonlocal done
            try:
                where.write(ds)
            except OSError:
                raise
            except Exception as exc:  # noqa: BLE001 - pydicom's many ways of refusing a dataset it cannot write
                raise ArchiveRefusedError(srv.label, f"sent an instance that cannot be written as DICOM "
                                                     f"({type(exc).__name__})") from None
            done += 1
            if progress:
                progress(done, len(listed))

        if missing:
            archive.fetch(study_uid, series_uid, missing, sink, stop)
    if stop():
        raise RetrieveCancelled(srv.label, f"retrieve cancelled after {done} of {len(listed)} instances (kept for "
                                           "a rerun)")
    still = set(listed) - where.present()
    if still:
        raise ArchiveNotFoundError(srv.label, f"sent {len(listed) - len(still)} of the {len(listed)} instances "
                                              f"listed (missing e.g. {sorted(still)[0]})")
    return where.finish()


def parse_ref(ref: str) -> tuple[str, str, str, str | None]:
    """``dicomweb://SERVER/STUDY[/SERIES]`` -> (protocol, server name, study UID, series UID or None)."""
    scheme, sep, rest = str(ref).partition("://")
    if not sep or scheme not in REF_SCHEMES:
        raise ArchiveConfigError(None, f"an archive reference is dicomweb://SERVER/STUDY_UID[/SERIES_UID] (or "
                                       f"dimse://...), got {ref!r}")
    parts = [p for p in rest.split("/") if p]
    if len(parts) not in (2, 3):
        raise ArchiveConfigError(None, f"an archive reference is {scheme}://SERVER/STUDY_UID[/SERIES_UID], got {ref!r}")
    study = check_uid(parts[1], "study UID")
    series_uid = check_uid(parts[2], "series UID") if len(parts) == 3 else None
    return REF_SCHEMES[scheme], parts[0], study, series_uid


def make_ref(server: str, study_uid: str, series_uid: str | None = None, protocol: str = "dicomweb") -> str:
    """The inverse of :func:`parse_ref`."""
    scheme = next(k for k, v in REF_SCHEMES.items() if v == protocol)
    return f"{scheme}://{server}/{study_uid}" + (f"/{series_uid}" if series_uid else "")


def load(ref: str, *, progress: Progress | None = None, cancel=None, cache=None, ask: Prompt | None = None,
         **options):
    """The volume of ``dicomweb://SERVER/STUDY[/SERIES]``: retrieved into the cache (or found there), then read
    by :func:`volumen.io.load` with ``options``. Without a series in the reference, ``series=UID`` (the
    command line's ``--series``) names it, or the study must hold one (else the error lists them)."""
    from ..io import load as load_file

    protocol, name, study_uid, series_uid = parse_ref(ref)
    chosen = options.pop("series", None)
    if series_uid is None and chosen:
        series_uid = check_uid(chosen, "series UID")
    if series_uid is None:
        found = series(name, study_uid, protocol=protocol, ask=ask)
        if len(found) > 1:
            raise MultipleSeriesError(ref, [(s.uid, s.description, s.n_instances or 0) for s in found])
        series_uid = found[0].uid
    folder = retrieve(name, study_uid, series_uid, protocol=protocol, cache=cache, progress=progress,
                      cancel=cancel, ask=ask)
    vol = load_file(folder, **options)
    vol.meta["archive_ref"] = make_ref(name, study_uid, series_uid, protocol)
    return vol


def send(server: str | Server, items: Iterable, *, protocol: str | None = None, ask: Prompt | None = None) -> int:
    """Store DICOM instances (pydicom datasets or file paths) on the server: STOW-RS or C-STORE. The count."""
    import pydicom

    datasets = [pydicom.dcmread(p) if isinstance(p, (str, Path)) else p for p in items]
    if not datasets:
        raise ArchiveConfigError(None, "nothing to send")
    with connect(server, protocol=protocol, ask=ask) as archive:
        return archive.store(datasets)
