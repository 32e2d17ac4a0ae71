"""The vessel profile the page plots under its slices (``volumen serve --report`` / ``--profile``): read from a
``report.json`` of ``volumen measure vessel`` or ``volumen fly --report`` (:meth:`volumen.analysis.Profile.to_dict`),
checked against the served scan (the centerline inside its box) and cut down to numbers: the sections' arc, point
and sizes, and the stenosis and the maximum. Nothing that names the scan: ``profile.json`` serves this."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

__all__ = ["read_profile", "PROFILE_COLUMNS", "LESION_FIELDS"]

#: the table's columns the page is told (mm, mm²), one value per section
PROFILE_COLUMNS = ("arc_mm", "x_mm", "y_mm", "z_mm", "area_mm2", "diameter_mm", "min_diameter_mm",
                   "max_diameter_mm", "inscribed_radius_mm")
#: the numbers of the stenosis and the maximum the page is told
LESION_FIELDS = ("arc_mm", "diameter_mm", "reference_mm", "percent", "flagged")


def read_profile(path, volume) -> dict:
    """The page's profile from ``path`` (a report folder or its ``report.json``) of a profile of ``volume``:
    ``{"table": {column: [values]}, "stenosis": {...}, "maximum": {...}, "length_mm"}``. A file that cannot be
    read, is no profile, or whose centerline leaves ``volume``'s box by more than a voxel raises ValueError
    (one line)."""
    p = Path(path)
    file = p / "report.json" if p.is_dir() else p
    try:
        report = json.loads(file.read_text(encoding="utf-8"))
        table = {c: np.asarray(report["table"][c], dtype=float) for c in PROFILE_COLUMNS}
        summary = report["summary"]
        lesions = {k: {f: summary[k][f] for f in LESION_FIELDS} for k in ("stenosis", "maximum")}
        length = float(summary["length_mm"])
    except OSError as exc:
        raise ValueError(f"cannot read the profile {file}: {exc.strerror or exc}") from None
    except (json.JSONDecodeError, UnicodeDecodeError, KeyError, TypeError, ValueError):
        raise ValueError(f"{file} is not a vessel profile (a report.json of `volumen measure vessel`)") from None
    n = len(table["arc_mm"])
    if n < 2 or any(v.shape != (n,) or not np.isfinite(v).all() for v in table.values()):
        raise ValueError(f"{file} is not a vessel profile: its table's columns are not {n} finite numbers each")
    _check_inside(np.stack([table[c] for c in ("x_mm", "y_mm", "z_mm")], axis=1), volume, file)
    return {"table": {c: v.tolist() for c, v in table.items()}, "length_mm": length,
            **{k: {f: (bool(v) if f == "flagged" else float(v)) for f, v in d.items()} for k, d in lesions.items()}}


def _check_inside(points: np.ndarray, volume, file) -> None:
    lo, hi = volume.bounds()
    slack = float(max(volume.spacing))
    if (points < lo - slack).any() or (points > hi + slack).any():
        raise ValueError(f"the profile {file} is not of this scan: its centerline leaves the scan's box")
