"""What a DICOM folder holds: one line per series, like dcm2niix's listing (no patient identity).

pydicom is imported when :func:`list_series` runs, not when :mod:`volumen.io` is imported.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["SeriesSummary", "list_series"]


@dataclass(frozen=True)
class SeriesSummary:
    """One image series of a folder: technical facts only.

    ``size`` is ``(columns, rows, slices)`` (slices counts frames of multi-frame files);
    ``unreadable`` counts the series' files whose header could not be read (the series
    then does not load).
    """

    uid: str
    number: str
    description: str
    modality: str
    size: tuple[int, int, int]
    files: int
    colour: bool
    sop_class: str
    transfer_syntax: str
    unreadable: int = 0

    def line(self) -> str:
        """``number  modality  cols x rows x slices  files  description  uid`` for listings."""
        c, r, n = self.size
        bad = f" (+{self.unreadable} unreadable)" if self.unreadable else ""
        return (f"{self.number or '-':>5}  {self.modality:<3} {c:>4} x {r:<4} x {n:<5} {self.files:>5} file(s)  "
                f"{self.description or '(no description)'}  {self.uid}{bad}")


def _number_key(s: SeriesSummary):
    try:
        return (0, float(s.number), s.uid)
    except ValueError:
        return (1, 0.0, s.uid)


def list_series(path, notes: list[str] | None = None) -> list[SeriesSummary]:
    """The image series under ``path`` (a DICOM folder, file or list of files), by SeriesNumber.

    Only headers are read. Unreadable files and files without images are skipped; their
    lines (path and cause) are appended to ``notes`` when a list is given. Raises the
    reader's typed errors when no series at all is found.
    """
    from ._dicom import scan

    found, found_notes, _ = scan(path)
    if notes is not None:
        notes.extend(found_notes)
    out = []
    for s in found.values():
        info, first = s.info, s.slices[0]
        out.append(SeriesSummary(
            uid=s.uid, number=info["series_number"], description=s.description, modality=info["modality"],
            size=(first.shape[1], first.shape[0], len(s.slices)), files=len(s.files),
            colour=info["samples_per_pixel"] == 3 or info["photometric"] == "PALETTE COLOR",
            sop_class=info["sop_class"], transfer_syntax=info["transfer_syntax"], unreadable=len(s.bad)))
    return sorted(out, key=_number_key)
