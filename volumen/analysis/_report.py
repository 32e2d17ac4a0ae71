"""A profile's report folder: ``profile.csv`` (the table), ``report.json`` (summary and table) and ``profile.png``.

What ``volumen measure vessel`` and ``volumen fly --report`` write. The folder is made; the three files are
written only once the picture is drawn, so a failure leaves nothing behind.
"""

from __future__ import annotations

import json
from pathlib import Path

__all__ = ["write_report"]


def write_report(profile, folder, volume=None) -> list[Path]:
    """Write the report of ``profile`` into ``folder`` (made if missing); the picture's CPR from ``volume`` when
    given. Returns the files' paths."""
    from ._figure import figure_png, profile_figure

    png = figure_png(profile_figure(profile, volume))
    report = json.dumps(profile.to_dict(), indent=1, default=float)
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    csv, js, pic = folder / "profile.csv", folder / "report.json", folder / "profile.png"
    profile.to_csv(csv)
    js.write_text(report, encoding="utf-8")
    pic.write_bytes(png)
    return [csv, js, pic]
