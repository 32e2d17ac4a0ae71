"""What a search asks (:class:`Query`) and what it finds (:class:`Study`, :class:`Series`), for both protocols.

A query turns into the same DICOM matching keys for QIDO-RS and C-FIND: ``PatientName`` and
``StudyDescription`` with the standard's wildcards (``*`` any run, ``?`` one character), ``PatientID`` and
``AccessionNumber``, ``StudyDate`` as a date or a range (``20240101-20241231``, ``-20241231``,
``20240101-``), ``ModalitiesInStudy``. Results are read from pydicom datasets (a C-FIND identifier, or QIDO's
JSON through ``Dataset.from_json``) so both protocols fill the same records.
"""

from __future__ import annotations

import re
from dataclasses import asdict, dataclass

from ..errors import ArchiveConfigError

__all__ = ["Query", "Study", "Series", "Studies", "check_uid", "printable", "STUDY_KEYS", "SERIES_KEYS",
           "STUDY_COLUMNS"]

_DATE = re.compile(r"^(\d{8})?(-(\d{8})?)?$")
_UID = re.compile(r"^[0-9]+(\.[0-9]+)*$")

#: the attributes a study search asks to be returned (beyond its matching keys)
STUDY_KEYS = ("StudyInstanceUID", "StudyDate", "StudyDescription", "PatientName", "PatientID", "AccessionNumber",
              "ModalitiesInStudy", "NumberOfStudyRelatedSeries", "NumberOfStudyRelatedInstances")
SERIES_KEYS = ("StudyInstanceUID", "SeriesInstanceUID", "SeriesNumber", "Modality", "SeriesDescription",
               "NumberOfSeriesRelatedInstances")


def _escape(char: str) -> str:
    code = ord(char)
    return f"\\x{code:02x}" if code < 0x100 else f"\\u{code:04x}" if code < 0x10000 else f"\\U{code:08x}"


def printable(text) -> str:
    """``text`` safe to print on a terminal: control characters (line ends, tabs, escapes, C1 controls) and
    invisible format characters (bidirectional overrides, zero-width marks, line separators) written as
    ``\\xNN`` / ``\\uNNNN``, so a server's field can neither move the cursor nor forge a row."""
    text = str(text)
    if text.isprintable():
        return text
    return "".join(c if c.isprintable() or c == " " else _escape(c) for c in text)


def check_uid(uid: str, what: str = "UID") -> str:
    """``uid`` when it is a DICOM UID (digits and dots, at most 64 characters), else a ValueError naming it.

    UIDs become folder names in the cache, so nothing else may pass.
    """
    uid = str(uid).strip()
    if len(uid) > 64 or not _UID.match(uid):
        raise ArchiveConfigError(None, f"{what} must be a DICOM UID (digits and dots, at most 64), got {uid!r}")
    return uid


@dataclass(frozen=True, kw_only=True)
class Query:
    """A study search; every field optional (all studies when none is given).

    Parameters
    ----------
    patient_name, patient_id, accession, description : str, optional
        Matched as DICOM does: exact, or with ``*`` / ``?`` wildcards (names ignore case on most servers).
    study_date : str, optional
        ``YYYYMMDD`` or a range ``YYYYMMDD-YYYYMMDD`` (either end may be left open).
    modality : str, optional
        A modality in the study (``CT``, ``MR``, ``SEG``...).
    study_uid : str, optional
        One study by its Study Instance UID.
    limit : int, optional
        At most this many studies.
    """

    patient_name: str | None = None
    patient_id: str | None = None
    study_date: str | None = None
    modality: str | None = None
    accession: str | None = None
    description: str | None = None
    study_uid: str | None = None
    limit: int | None = None

    def __post_init__(self):
        if self.study_date is not None and (not _DATE.match(self.study_date) or self.study_date in ("", "-")):
            raise ArchiveConfigError(None, f"study date must be YYYYMMDD or a range YYYYMMDD-YYYYMMDD (either end "
                                           f"may be open), got {self.study_date!r}")
        if self.study_uid is not None:
            check_uid(self.study_uid, "study UID")
        if self.limit is not None and self.limit < 1:
            raise ArchiveConfigError(None, f"limit must be at least 1, got {self.limit}")

    def filters(self) -> dict[str, str]:
        """The matching keys, DICOM keyword -> value (only those given)."""
        keys = {"PatientName": self.patient_name, "PatientID": self.patient_id, "StudyDate": self.study_date,
                "ModalitiesInStudy": self.modality, "AccessionNumber": self.accession,
                "StudyDescription": self.description, "StudyInstanceUID": self.study_uid}
        return {k: v for k, v in keys.items() if v not in (None, "")}

    def to_dict(self) -> dict:
        return {k: v for k, v in asdict(self).items() if v is not None}


def _text(ds, keyword: str) -> str:
    value = ds.get(keyword, "")
    if value is None:
        return ""
    if not isinstance(value, str) and hasattr(value, "__iter__") and not hasattr(value, "original_string"):
        return "\\".join(str(v) for v in value)
    return str(value)


def _int(ds, keyword: str) -> int | None:
    try:
        return int(ds.get(keyword))
    except (TypeError, ValueError):
        return None


@dataclass(frozen=True)
class Study:
    """One study found on an archive. Patient name and ID are here because the user searched for them; they
    are shown in ``find``'s table and the dialog, never logged."""

    uid: str
    date: str = ""
    description: str = ""
    patient_name: str = ""
    patient_id: str = ""
    accession: str = ""
    modalities: tuple[str, ...] = ()
    n_series: int | None = None
    n_instances: int | None = None

    @classmethod
    def from_dataset(cls, ds) -> Study:
        mods = ds.get("ModalitiesInStudy", "")
        mods = (mods,) if isinstance(mods, str) else tuple(str(m) for m in mods)
        return cls(uid=_text(ds, "StudyInstanceUID"), date=_text(ds, "StudyDate"),
                   description=_text(ds, "StudyDescription"), patient_name=_text(ds, "PatientName"),
                   patient_id=_text(ds, "PatientID"), accession=_text(ds, "AccessionNumber"),
                   modalities=tuple(m for m in mods if m), n_series=_int(ds, "NumberOfStudyRelatedSeries"),
                   n_instances=_int(ds, "NumberOfStudyRelatedInstances"))


#: the columns of a table of studies (``volumen pacs find``, the notebook)
STUDY_COLUMNS = ("date", "modality", "series", "patient", "patient ID", "accession", "description",
                 "StudyInstanceUID")


class Studies(list):
    """A list of :class:`Study` that shows itself as a table in Jupyter (what ``volumen.pacs.find`` returns)."""

    def rows(self) -> list[list[str]]:
        """One row of :data:`STUDY_COLUMNS` per study."""
        return [[printable(v) for v in (s.date or "-", "/".join(s.modalities) or "-",
                                        "?" if s.n_series is None else str(s.n_series), s.patient_name or "-",
                                        s.patient_id or "-", s.accession or "-", s.description or "-", s.uid)]
                for s in self]

    def _repr_html_(self) -> str:
        from html import escape

        head = "".join(f"<th>{escape(c)}</th>" for c in STUDY_COLUMNS)
        body = "".join("<tr>" + "".join(f"<td>{escape(v)}</td>" for v in row) + "</tr>" for row in self.rows())
        return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


@dataclass(frozen=True)
class Series:
    """One series of a study (technical facts only)."""

    uid: str
    study_uid: str
    number: str = ""
    modality: str = ""
    description: str = ""
    n_instances: int | None = None

    @classmethod
    def from_dataset(cls, ds, study_uid: str = "") -> Series:
        return cls(uid=_text(ds, "SeriesInstanceUID"), study_uid=_text(ds, "StudyInstanceUID") or study_uid,
                   number=_text(ds, "SeriesNumber"), modality=_text(ds, "Modality"),
                   description=_text(ds, "SeriesDescription"), n_instances=_int(ds, "NumberOfSeriesRelatedInstances"))
