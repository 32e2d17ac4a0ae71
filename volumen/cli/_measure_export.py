"""``volumen measure export SESSION -o report.dcm``: a session's measurements as a DICOM Comprehensive 3D SR
(TID 1500, in the scan's study, referencing its images), CSV or JSON, by the output's suffix.

SESSION is the app's session JSON (its scan is ``scene.volume``), a measurements JSON file (give ``--scan``) or an
SR. The measurements must have been made on that scan: a measurement of another scan is one line and nothing is
written.
"""

from __future__ import annotations

import json
from pathlib import Path

__all__ = ["register", "run", "OUTPUTS"]

OUTPUTS = ("out",)
#: output suffix -> what is written
FORMATS = {".dcm": "DICOM SR", ".csv": "CSV", ".json": "JSON"}


def register(acts):
    p = acts.add_parser("export", help="write a session's measurements as a DICOM SR (.dcm), CSV or JSON")
    p.add_argument("session", help="a session JSON (app or page), a measurements JSON, or a DICOM SR")
    p.add_argument("-o", "--out", required=True, help="report.dcm (DICOM SR), .csv or .json")
    p.add_argument("--scan", help="the scan they were made on (default: the session's scene.volume)")
    return p


def _scan_ref(args) -> str | None:
    if args.scan:
        return args.scan
    try:
        d = json.loads(Path(args.session).read_text(encoding="utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError):
        return None  # an SR: its scan comes from --scan
    return (d.get("scene") or {}).get("volume") if isinstance(d, dict) else None


def run(args):
    from volumen.app._session import resolve_volume
    from volumen.errors import MeasurementError
    from volumen.measure import load_measurements, make_sr, save_measurements

    out = Path(args.out)
    if out.suffix.lower() not in FORMATS:
        raise ValueError(f"-o {out}: the suffix says the format: {', '.join(f'{k} ({v})' for k, v in FORMATS.items())}")
    ref = _scan_ref(args)
    volume = resolve_volume(ref) if ref else None
    items = load_measurements(args.session, volume=volume)
    if not items:
        raise MeasurementError(f"{args.session}: holds no measurements")
    if out.suffix.lower() == ".dcm":
        if volume is None:
            raise MeasurementError(f"{args.session}: names no scan; give --scan (the DICOM series measured)")
        make_sr(items, volume).save_as(out, enforce_file_format=True)
    else:
        save_measurements(items, out)
    print(f"wrote {len(items)} measurement(s) to {out} ({FORMATS[out.suffix.lower()]})")
    return 0
