"""What every archive client offers: the one interface ``volumen.pacs`` talks to, whatever the protocol.

:class:`ArchiveClient` is the common interface of :class:`~._dicomweb.DicomWebArchive` (DICOMweb: QIDO-RS,
WADO-RS, STOW-RS) and :class:`~._dimse.DimseArchive` (DIMSE: C-ECHO, C-FIND, C-GET or C-MOVE, C-STORE);
:func:`~._api.connect` yields one, and ``find``, ``series``, ``retrieve`` and ``send`` use nothing else.
A client for another protocol is a class with these members (``tests/pacs/test_archive_client.py`` checks
both clients against it, name for name and parameter for parameter).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import Protocol, runtime_checkable

from ._config import Server
from ._records import Query, Series, Study

__all__ = ["ArchiveClient"]


@runtime_checkable
class ArchiveClient(Protocol):
    """One archive, reached through one protocol; ``server`` is its entry of ``servers.toml``."""

    server: Server

    def close(self) -> None:
        """Let go of the connection (a no-op where each call opens its own association)."""

    def echo(self) -> float:
        """Seconds a round trip to the archive took."""

    def find_studies(self, query: Query) -> list[Study]:
        """The studies matching ``query``."""

    def find_series(self, study_uid: str) -> list[Series]:
        """The series of study ``study_uid``."""

    def list_instances(self, study_uid: str, series_uid: str) -> list[str]:
        """The SOP Instance UIDs of a series."""

    def fetch(self, study_uid: str, series_uid: str, sop_uids: list[str], sink: Callable, stop: Callable[[], bool]):
        """Each instance of ``sop_uids`` into ``sink(dataset)``, in turn; returns early when ``stop()``."""

    def store(self, datasets: Iterable) -> int:
        """Send ``datasets`` to the archive; the number stored."""
