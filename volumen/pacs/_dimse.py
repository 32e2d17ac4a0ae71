"""DIMSE with ``pynetdicom``: C-ECHO, C-FIND (study, series, image level), C-GET, C-MOVE to volumen's own
storage SCP, and C-STORE, over the Study Root information model.

Instances arrive as C-STORE sub-operations, each handed to the caller's sink as it comes. pynetdicom's
logging of request and response identifiers (which hold patient names) is turned off, so nothing this
module does writes patient identity to a log. Failures become the typed errors of :mod:`volumen.errors`.
"""

from __future__ import annotations

import threading
import time
import warnings
from collections.abc import Callable, Iterable

from ..errors import ArchiveError, ArchiveNotFoundError, ArchiveRefusedError, ArchiveUnreachableError
from ._config import Server
from ._records import SERIES_KEYS, STUDY_KEYS, Query, Series, Study

__all__ = ["DimseArchive"]

_PENDING = (0xFF00, 0xFF01)
_OK, _OUT_OF_RESOURCES, _CANNOT_STORE = 0x0000, 0xA702, 0xC211
_SOME_FAILED = 0xB000  # C-GET / C-MOVE: sub-operations complete, one or more failed (counted in the status)
_STORE_WARNINGS = (0xB000, 0xB006, 0xB007)  # C-STORE: coerced, elements discarded, data set mismatch
#: transfer syntaxes C-GET proposes, one presentation context each, for each SOP class of the series: an archive
#: sends an instance as stored when one matches (it may be unable to transcode, e.g. Orthanc from JPEG 2000),
#: and volumen's DICOM reader decodes them all
_GET_SYNTAXES = ("1.2.840.10008.1.2.1", "1.2.840.10008.1.2", "1.2.840.10008.1.2.4.50", "1.2.840.10008.1.2.4.51",
                 "1.2.840.10008.1.2.4.57", "1.2.840.10008.1.2.4.70", "1.2.840.10008.1.2.4.80",
                 "1.2.840.10008.1.2.4.81", "1.2.840.10008.1.2.4.90", "1.2.840.10008.1.2.4.91", "1.2.840.10008.1.2.5",
                 "1.2.840.10008.1.2.1.99", "1.2.840.10008.1.2.2")


def _pynetdicom():
    import pynetdicom
    from pynetdicom import _config

    _config.LOG_REQUEST_IDENTIFIERS = False  # identifiers hold patient names: never in a log
    _config.LOG_RESPONSE_IDENTIFIERS = False
    return pynetdicom


def _identifier(level: str, keys: Iterable[str], filters: dict[str, str]):
    from pydicom import Dataset

    ds = Dataset()
    ds.QueryRetrieveLevel = level
    for key in keys:
        setattr(ds, key, "")
    for key, value in filters.items():
        setattr(ds, key, value)
    return ds


#: associations requested when a reachable archive answers with an abort (a rejection it hung up on at once is
#: seen as one under load: twice was not always enough in a loaded test run)
_ASSOCIATE_ATTEMPTS = 3

class DimseArchive:
    """One DIMSE application entity (``server.ae_title`` at ``server.host:server.port``)."""

    def __init__(self, server: Server, ask=None):
        self.server = server
        self._sop_classes: tuple[str, ...] = ()  # of the series last listed: the storage contexts C-GET proposes

    def close(self) -> None:
        pass

    # -- associations ---------------------------------------------------------
    # (an abort from a reachable archive is asked again up to _ASSOCIATE_ATTEMPTS times in all)
    def _ae(self):
        pn = _pynetdicom()
        ae = pn.AE(ae_title=self.server.calling_ae_title)
        t = self.server.timeout
        ae.acse_timeout = ae.dimse_timeout = ae.network_timeout = t
        ae.connection_timeout = min(t, 10.0)
        return ae

    def _associate(self, contexts, *, storage: tuple[str, ...] = (), handlers=None):
        """An established association proposing ``contexts`` and, for C-GET, storage contexts for the SOP classes
        ``storage`` (one per transfer syntax of :data:`_GET_SYNTAXES`) with volumen in the SCP role."""
        pn = _pynetdicom()
        ae = self._ae()
        for cx in contexts:
            ae.add_requested_context(cx)
        roles = None
        if storage:  # C-GET: the archive sends C-STORE requests back over this association
            for sop_class in storage:
                for ts in _GET_SYNTAXES[: max(1, (127 - len(contexts)) // len(storage))]:
                    ae.add_requested_context(sop_class, [ts])
            roles = [pn.build_role(uid, scp_role=True) for uid in storage]
        for attempt in range(_ASSOCIATE_ATTEMPTS):
            assoc = ae.associate(self.server.host, self.server.port, ae_title=self.server.ae_title, ext_neg=roles,
                                 evt_handlers=handlers)
            if (assoc.is_established or assoc.is_rejected or attempt == _ASSOCIATE_ATTEMPTS - 1
                    or self._reachable() is not None):
                break  # else ask again: an archive that rejects and hangs up at once is seen, under load, to abort
        if assoc.is_established:
            return assoc
        if assoc.is_rejected:
            raise ArchiveRefusedError(self.server.label, f"rejected the association (is its AE title "
                                                         f"{self.server.ae_title}, and is volumen's, "
                                                         f"{self.server.calling_ae_title}, known to it?)")
        reachable = self._reachable()
        if reachable is not None:
            raise ArchiveUnreachableError(self.server.label, f"did not answer ({reachable})")
        raise ArchiveRefusedError(self.server.label, "aborted the association")

    def _reachable(self) -> str | None:
        """None when a TCP connection to the server opens, else why not (pynetdicom reports both as aborted)."""
        import socket

        try:
            with socket.create_connection((self.server.host, self.server.port), timeout=min(self.server.timeout, 5)):
                return None
        except OSError as exc:
            return (exc.strerror or type(exc).__name__).lower()

    def _run(self, what: str, responses) -> list:
        """The identifiers of pending responses; a failure status, a lost connection, more matches than
        ``max_answer_mb`` holds at 1 KiB each, or responses past ``deadline`` are errors."""
        out = []
        end = time.monotonic() + self.server.deadline
        most = int(self.server.max_answer_mb * 1024)
        for status, identifier in responses:
            if time.monotonic() > end:
                raise ArchiveUnreachableError(self.server.label, f"did not finish the {what} within "
                                                                 f"{self.server.deadline:g} s (deadline, servers.toml)")
            if len(out) > most:
                raise ArchiveRefusedError(self.server.label, f"sent more than {most} matches to the {what} "
                                                             "(max_answer_mb in servers.toml, 1 KiB a match)")
            code = getattr(status, "Status", None)
            if code is None:
                raise ArchiveUnreachableError(self.server.label, f"the connection broke during the {what}")
            if code in _PENDING:
                if identifier is not None:
                    out.append(identifier)
            elif code == 0xFE00:
                raise ArchiveRefusedError(self.server.label, f"the {what} was cancelled")
            elif code not in (_OK, _SOME_FAILED):
                raise ArchiveRefusedError(self.server.label, f"the {what} failed (status 0x{code:04X})")
            else:
                failed = int(status.get("NumberOfFailedSuboperations", 0) or 0)
                if failed:
                    raise ArchiveRefusedError(self.server.label, f"the {what}: {failed} instance(s) failed")
        return out

    def _find(self, level: str, keys, filters: dict[str, str]) -> list:
        from pynetdicom.sop_class import StudyRootQueryRetrieveInformationModelFind as FIND

        assoc = self._associate([FIND])
        try:
            with warnings.catch_warnings():  # pydicom's warnings about odd values quote the values
                warnings.simplefilter("ignore")
                return self._run("C-FIND", assoc.send_c_find(_identifier(level, keys, filters), FIND))
        finally:
            assoc.release()

    # -- the interface shared with DicomWebArchive ------------------------------
    def echo(self) -> float:
        from pynetdicom.sop_class import Verification

        t0 = time.perf_counter()
        assoc = self._associate([Verification])
        try:
            status = assoc.send_c_echo()
        finally:
            assoc.release()
        if getattr(status, "Status", None) != _OK:
            raise ArchiveRefusedError(self.server.label, "C-ECHO failed")
        return time.perf_counter() - t0

    def _records(self, what: str, make: Callable, found: list) -> list:
        """``make(ds)`` of each identifier; an identifier whose values do not read is one error naming the search."""
        try:
            with warnings.catch_warnings():  # pydicom's warnings about odd values quote the values
                warnings.simplefilter("ignore")
                return [make(ds) for ds in found]
        except (ValueError, TypeError, KeyError, AttributeError, IndexError, OverflowError) as exc:
            raise ArchiveRefusedError(self.server.label, f"the {what}: unexpected answer "
                                                         f"({type(exc).__name__})") from None

    def find_studies(self, query: Query) -> list[Study]:
        found = self._records("study search", Study.from_dataset, self._find("STUDY", STUDY_KEYS, query.filters()))
        return found[: query.limit] if query.limit else found

    def find_series(self, study_uid: str) -> list[Series]:
        found = self._find("SERIES", SERIES_KEYS, {"StudyInstanceUID": study_uid})
        return self._records("series search", lambda ds: Series.from_dataset(ds, study_uid), found)

    def list_instances(self, study_uid: str, series_uid: str) -> list[str]:
        found = self._find("IMAGE", ("SOPInstanceUID", "SOPClassUID"), {"StudyInstanceUID": study_uid,
                                                                         "SeriesInstanceUID": series_uid})
        self._sop_classes = tuple(sorted({str(ds.SOPClassUID) for ds in found if ds.get("SOPClassUID")}))
        return [str(ds.SOPInstanceUID) for ds in found if "SOPInstanceUID" in ds]

    def fetch(self, study_uid: str, series_uid: str, sop_uids: list[str], sink: Callable, stop: Callable[[], bool]):
        """C-GET (or C-MOVE, per ``server.retrieve``) the instances ``sop_uids`` of a series into ``sink``."""
        filters = {"StudyInstanceUID": study_uid, "SeriesInstanceUID": series_uid,
                   "SOPInstanceUID": "\\".join(sop_uids)}
        received = _Receiver(sink, stop)
        try:
            (self._move if self.server.retrieve == "move" else self._get)(filters, received)
        except ArchiveRefusedError:
            if not stop() and received.error is None:  # else: failed sub-operations are ours (cancel, disk)
                raise
        received.check(self.server.label)

    def _get(self, filters: dict, received: _Receiver) -> None:
        from pynetdicom import StoragePresentationContexts, evt
        from pynetdicom.sop_class import StudyRootQueryRetrieveInformationModelGet as GET

        classes = self._sop_classes or tuple(cx.abstract_syntax for cx in StoragePresentationContexts[:126])
        assoc = self._associate([GET], storage=classes, handlers=[(evt.EVT_C_STORE, received.handle)])
        received.on_stop = lambda: assoc.send_c_cancel(1, query_model=GET)
        try:
            self._run("C-GET", assoc.send_c_get(_identifier("IMAGE", (), filters), GET))
        finally:
            assoc.release()

    def _move(self, filters: dict, received: _Receiver) -> None:
        from pynetdicom import ALL_TRANSFER_SYNTAXES, StoragePresentationContexts, evt
        from pynetdicom.sop_class import StudyRootQueryRetrieveInformationModelMove as MOVE

        if self.server.store_port is None:
            raise ArchiveRefusedError(self.server.label, "C-MOVE needs store_port (the port of volumen's storage "
                                                         "SCP, known to the archive) in servers.toml")
        ae = self._ae()
        for cx in StoragePresentationContexts:  # the archive proposes what it stores: accept it as it is
            ae.add_supported_context(cx.abstract_syntax, ALL_TRANSFER_SYNTAXES)
        scp = ae.start_server(("", self.server.store_port), block=False,
                              evt_handlers=[(evt.EVT_C_STORE, received.handle)])
        try:
            assoc = self._associate([MOVE])
            received.on_stop = lambda: assoc.send_c_cancel(1, query_model=MOVE)
            try:
                self._run("C-MOVE", assoc.send_c_move(_identifier("IMAGE", (), filters),
                                                      self.server.calling_ae_title, MOVE))
            finally:
                assoc.release()
        finally:
            scp.shutdown()

    def store(self, datasets: Iterable) -> int:
        """C-STORE each dataset (one association, a presentation context per SOP class and transfer syntax)."""
        from pydicom.uid import ExplicitVRLittleEndian, ImplicitVRLittleEndian

        datasets = list(datasets)
        contexts: dict[str, set[str]] = {}
        for ds in datasets:
            ts = getattr(getattr(ds, "file_meta", None), "TransferSyntaxUID", None) or ExplicitVRLittleEndian
            contexts.setdefault(str(ds.SOPClassUID), {str(ImplicitVRLittleEndian)}).add(str(ts))
        ae = self._ae()
        for sop_class, syntaxes in contexts.items():
            ae.add_requested_context(sop_class, sorted(syntaxes))
        assoc = self._associate([cx.abstract_syntax for cx in ae.requested_contexts])
        try:
            for ds in datasets:
                status = assoc.send_c_store(ds)
                code = getattr(status, "Status", None)
                if code is None:
                    raise ArchiveUnreachableError(self.server.label, "the connection broke during the C-STORE")
                if code != _OK and code not in _STORE_WARNINGS:
                    raise ArchiveRefusedError(self.server.label, f"refused instance {ds.SOPInstanceUID} "
                                                                 f"(status 0x{code:04X})")
        finally:
            assoc.release()
        return len(datasets)


class _Receiver:
    """The C-STORE handler of C-GET / C-MOVE: each instance to ``sink``; once ``stop()`` (or a failed store) it
    refuses them and calls ``on_stop`` once (a C-CANCEL of the retrieve, so the archive sends no more)."""

    def __init__(self, sink: Callable, stop: Callable[[], bool]):
        self.sink, self.stop = sink, stop
        self.error: BaseException | None = None
        self.count = 0
        self.lock = threading.Lock()
        self.on_stop: Callable[[], None] | None = None

    def handle(self, event) -> int:
        if self.error is not None or self.stop():
            if self.on_stop is not None:
                self.on_stop, cancel = None, self.on_stop
                cancel()
            return _OUT_OF_RESOURCES
        ds = event.dataset
        ds.file_meta = event.file_meta
        try:
            with self.lock:
                self.sink(ds)
                self.count += 1
        except Exception as exc:  # noqa: BLE001 - kept and raised on the caller's thread by check()
            self.error = exc
            return _CANNOT_STORE
        return _OK

    def check(self, label: str) -> None:
        if self.error is not None:
            if isinstance(self.error, (ArchiveError, OSError)):
                raise self.error
            raise ArchiveRefusedError(label, f"an instance could not be stored ({self.error})")
        if self.count == 0 and not self.stop():
            raise ArchiveNotFoundError(label, "sent no instance (deleted since it was listed?)")
