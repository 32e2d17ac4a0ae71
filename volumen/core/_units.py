"""Numbers a user reads, in their units' precision: Hounsfield units whole, millimetres to a tenth, other data
values to four significant digits (a float MRI's 335.981 reads 336, a probability's 0.123456 reads 0.1235).

Every line a command prints about values or lengths formats them here, so ``wall threshold 298.972 (lumen 462,
wall 135.944)`` reads ``wall threshold 299 (lumen 462, wall 136)`` in every command alike.
"""

from __future__ import annotations

import math

__all__ = ["value_text", "mm_text", "range_text", "values_of"]


def value_text(value: float, units: str = "") -> str:
    """``value`` in the data's units: whole for Hounsfield units (``units`` ``"HU"``, ``"HU+1000"``), else four
    significant digits; ``nan`` / ``inf`` as Python writes them, ``-0`` as ``0``."""
    v = float(value) + 0.0
    if not math.isfinite(v):
        return f"{v}"
    if units.upper().startswith("HU"):
        return f"{round(v) + 0:d}"
    text = f"{v:.4g}"
    return f"{round(v):d}" if "e+" in text and abs(v) < 1e15 else text


def range_text(lo: float, hi: float, units: str = "") -> str:
    """``lo..hi`` in the data's units (:func:`value_text`)."""
    return f"{value_text(lo, units)}..{value_text(hi, units)}"


def values_of(volume) -> dict:
    """The keywords of :func:`value_text` for ``volume``'s values: its units (a threshold half-way between two
    integers of a scan in other units is a value of its own: 310.5 stays 310.5)."""
    return {"units": getattr(volume, "units", "") or ""}


def mm_text(value: float) -> str:
    """A length or coordinate in millimetres, to a tenth of a millimetre (``-0.0`` reads ``0.0``)."""
    v = round(float(value), 1)
    return f"{v + 0.0:.1f}"
