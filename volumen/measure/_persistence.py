"""Measurements in files: a session's ``"measurements"`` list (the app's session JSON, the page's state), a JSON
file of their own, CSV for spreadsheets, and reading any of these or a DICOM SR back (:func:`load_measurements`).

JSON holds each measurement's ``to_dict`` (:meth:`Measurements.to_dicts`): world RAS+ mm, the plane and shape of a
region, its statistics and the scan it was made on; a session without measurements has none.
"""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path

from ..errors import MeasurementError
from ._model import Measurements, Scan

__all__ = ["SESSION_KEY", "load_measurements", "save_measurements", "session_measurements", "check_scan",
           "check_study"]

#: where a session (app JSON, page state) keeps its measurements
SESSION_KEY = "measurements"
#: the version of a measurements JSON file of its own
FILE_VERSION = 1


def check_scan(items, volume, where: str = "") -> None:
    """Raise :class:`MeasurementError` where a measurement was made on another scan than ``volume``."""
    here = Scan.of(volume)
    for m in items:
        if not m.scan.matches(here):
            named = f" {m.label!r}" if m.label else ""
            raise MeasurementError(f"{where + ': ' if where else ''}the {m.kind}{named} was measured on scan "
                                   f"{m.scan.text()}, not on the scan loaded ({here.text()})")


def session_measurements(session: dict) -> Measurements:
    """The measurements a session dict holds (none where it has no :data:`SESSION_KEY`)."""
    return Measurements.from_dicts(session.get(SESSION_KEY, []))


def _study_of(volume) -> str:
    """The StudyInstanceUID of a scan read from DICOM ("" for one that was not)."""
    from ..errors import LabelError
    from ..pacs import source_images

    try:
        return str(source_images(volume)[0].get("StudyInstanceUID", ""))
    except LabelError:
        return ""


def check_study(facts, volume, path) -> None:
    """Raise :class:`MeasurementError` where the SR at ``path`` (its :class:`SRFacts`) is of another study or series
    than ``volume``."""
    study = _study_of(volume)
    if study and facts.study_uid != study:
        raise MeasurementError(f"{path}: an SR of study {facts.study_uid}, not of the scan's study {study}")


def _is_dicom(path: Path) -> bool:
    with open(path, "rb") as f:
        head = f.read(132)
    return head[128:132] == b"DICM"


def load_measurements(path, volume=None) -> Measurements:
    """The measurements in ``path``: a DICOM SR (TID 1500), a session JSON or a measurements JSON file.

    With ``volume`` (the scan loaded) they are checked to belong to it: the same series (and, for an SR, the same
    study).

    Raises
    ------
    MeasurementError
        A measurement of another scan, an SR of another study, a file that holds no measurements.
    """
    path = Path(path)
    if not path.is_file():
        raise MeasurementError(f"{path}: no such file")
    if _is_dicom(path):
        from ._sr_read import read_sr

        items, facts = read_sr(path)
        if volume is not None:
            check_study(facts, volume, path)
    else:
        try:
            d = json.loads(path.read_text(encoding="utf-8"))
        except (UnicodeDecodeError, json.JSONDecodeError) as exc:
            raise MeasurementError(f"{path}: neither a DICOM SR nor JSON ({exc})") from None
        if not isinstance(d, dict) or SESSION_KEY not in d:
            raise MeasurementError(f"{path}: holds no {SESSION_KEY!r} list")
        items = session_measurements(d)
    if volume is not None:
        check_scan(items, volume, str(path))
    return items


def _write_atomic(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", encoding="utf-8", newline="") as f:
            f.write(text)
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise


def save_measurements(items, path) -> Path:
    """Write ``items`` to ``path``: CSV for a ``.csv`` name, else JSON (``{"version", "measurements"}``)."""
    path = Path(path)
    items = Measurements(items)
    if path.suffix.lower() == ".csv":
        _write_atomic(path, items.to_csv())
    else:
        _write_atomic(path, json.dumps({"version": FILE_VERSION, SESSION_KEY: items.to_dicts()}, indent=1) + "\n")
    return path
