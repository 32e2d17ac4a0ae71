"""Names tables of label maps: which value is which structure, in which colour.

Read formats (detected from the content):

* JSON: ``{"1": "spleen", ...}`` (TotalSegmentator's class map), ``{"spleen": 1, ...}``,
  or a list of ``{"value": 1, "name": "spleen", "color": [r, g, b]}`` (0..1 or 0..255);
* CSV: ``value,name[,r,g,b]`` with an optional header line;
* ITK-SNAP label descriptions: ``IDX R G B A VIS MSH "LABEL"`` (0..255);
* 3D Slicer colour tables (``.ctbl`` / ``.txt``): ``value name r g b a`` (0..255).

Lines starting with ``#`` are comments. The result is ``{value: (name, rgb or None)}``.
"""

from __future__ import annotations

import csv
import io
import json
import shlex
from pathlib import Path

from ..errors import LabelError

__all__ = ["read_names_table"]


def _rgb(values) -> tuple[float, float, float] | None:
    if values is None or len(values) < 3:
        return None
    c = [float(v) for v in values[:3]]
    scale = 255.0 if max(c) > 1.0 else 1.0
    return (c[0] / scale, c[1] / scale, c[2] / scale)


def _from_json(obj) -> dict:
    if isinstance(obj, dict) and all(str(k).strip().isdigit() for k in obj):
        return {int(k): (str(v), None) for k, v in obj.items()}
    if isinstance(obj, dict) and all(isinstance(v, int) for v in obj.values()):
        return {int(v): (str(k), None) for k, v in obj.items()}
    if isinstance(obj, list):
        out = {}
        for row in obj:
            value = row.get("value", row.get("label", row.get("labelValue")))
            name = row.get("name", row.get("label_name", row.get("terminology", "")))
            out[int(value)] = (str(name), _rgb(row.get("color")))
        return out
    raise ValueError("expected {value: name}, {name: value} or a list of {value, name, color}")


def _from_rows(rows: list[list[str]]) -> dict:
    out = {}
    for row in rows:
        if not row or row[0].startswith("#") or not row[0].strip().lstrip("-").isdigit():
            continue  # comments and a header line
        value = int(row[0])
        if len(row) >= 8 and all(_is_number(x) for x in row[1:7]):  # ITK-SNAP: IDX R G B A VIS MSH "LABEL"
            name, rgb = row[7], _rgb(row[1:4])
        else:  # CSV / Slicer: value name [r g b [a]]
            name, rgb = row[1], _rgb(row[2:5]) if len(row) >= 5 else None
        if value != 0:
            out[value] = (name.strip(), rgb)
    return out


def _is_number(s: str) -> bool:
    try:
        float(s)
    except ValueError:
        return False
    return True


def read_names_table(path) -> dict[int, tuple[str, tuple[float, float, float] | None]]:
    """``{label value: (name, linear rgb 0..1 or None)}`` from a JSON, CSV, ITK-SNAP or Slicer table.

    Raises
    ------
    LabelError
        The file cannot be read or holds no ``value -> name`` rows.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError) as e:
        raise LabelError(path, f"cannot read the names table ({e.__class__.__name__}: {e})") from None
    try:
        if text.lstrip().startswith(("{", "[")):
            table = _from_json(json.loads(text))
        elif path.suffix.lower() == ".csv" or text.count(",") >= text.count("\n"):
            table = _from_rows([r for r in csv.reader(io.StringIO(text))])
        else:
            table = _from_rows([shlex.split(line, comments=False) for line in text.splitlines() if line.strip()])
    except (ValueError, TypeError, AttributeError, KeyError) as e:
        raise LabelError(path, f"not a names table: {e}") from None
    table = {v: t for v, t in table.items() if v != 0}
    if not table:
        raise LabelError(path, "the names table holds no 'value -> name' rows")
    return table
