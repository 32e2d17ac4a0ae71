"""Measurements as rows of a table: an HTML table for Jupyter, CSV for spreadsheets.

Every measurement gives :meth:`row`: a flat dict of its kind, its values with their units written out, and the
scan it was made on. Numbers read in their units' precision (``core.mm_text``, ``core.value_text``).
"""

from __future__ import annotations

import csv
import html
import io

__all__ = ["html_table", "csv_text", "COLUMNS"]

#: the columns of a table of measurements, in order; a row leaves out what does not apply to its kind
COLUMNS = ("kind", "label", "value", "unit", "mean", "sd", "min", "max", "median", "area_mm2", "voxels",
           "values_unit", "points_mm", "plane", "scan")


def _columns(rows: list[dict]) -> list[str]:
    """The columns of :data:`COLUMNS` that some row fills."""
    return [c for c in COLUMNS if any(r.get(c) not in (None, "") for r in rows)]


def html_table(rows: list[dict]) -> str:
    """An HTML table of ``rows`` (each a :meth:`row` dict), escaped."""
    cols = _columns(rows)
    head = "".join(f"<th>{html.escape(c)}</th>" for c in cols)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(str(r.get(c, '')))}</td>" for c in cols) + "</tr>"
                   for r in rows)
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def csv_text(rows: list[dict]) -> str:
    """``rows`` as CSV text with a header line (every column of :data:`COLUMNS` that some row fills)."""
    out = io.StringIO()
    writer = csv.DictWriter(out, fieldnames=_columns(rows), extrasaction="ignore", lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    return out.getvalue()
