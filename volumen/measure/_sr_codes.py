"""The coded concepts and units of volumen's measurements in a DICOM SR, declared once for the writer and the
reader: what each number is called (SNOMED CT), its unit (UCUM), and how a measurement's kind and label travel
in the tracking identifier.

World points are RAS+ in volumen and LPS+ in DICOM (docs/design.md section 2): :data:`LPS` flips x and y.
"""

from __future__ import annotations

import numpy as np

__all__ = ["LPS", "STATISTICS", "tracking_text", "parse_tracking", "name_code", "unit_code", "unit_of"]

LPS = np.array([-1.0, -1.0, 1.0])

#: a region's numbers: RegionStats field -> (SNOMED CT code, meaning); the units are the scan's (area and count apart)
STATISTICS = {
    "mean": ("373098007", "Mean"), "sd": ("386136009", "Standard Deviation"), "min": ("255605001", "Minimum"),
    "max": ("56851009", "Maximum"), "median": ("373099004", "Median"), "area_mm2": ("42798000", "Area"),
}
#: the other numbers: name -> (scheme, code, meaning)
NAMES = {
    "length": ("SCT", "410668003", "Length"), "angle": ("SCT", "1483009", "Angle"),
    "volume": ("SCT", "118565006", "Volume"), "voxels": ("NCIt", "C25463", "Count"),
}
#: UCUM units: volumen's unit text -> (code, meaning)
UNITS = {"mm": ("mm", "millimeter"), "mm2": ("mm2", "square millimeter"), "deg": ("deg", "degree"),
         "ml": ("ml", "milliliter"), "HU": ("[hnsf'U]", "Hounsfield unit"), "voxels": ("{voxels}", "voxels"),
         "": ("1", "no units")}

#: the prefix of volumen's tracking identifiers: "volumen distance 3", "volumen region ellipse 1: left kidney"
PREFIX = "volumen"


def _coded(scheme: str, value: str, meaning: str):
    import highdicom as hd

    return hd.sr.CodedConcept(value=value, scheme_designator=scheme, meaning=meaning)


def name_code(field: str):
    """The concept naming the number ``field`` (a key of :data:`STATISTICS` or :data:`NAMES`)."""
    if field in STATISTICS:
        return _coded("SCT", *STATISTICS[field])
    return _coded(*NAMES[field])


def unit_code(units: str):
    """The UCUM unit of volumen's ``units`` (another scan's units as a UCUM annotation, ``{...}``)."""
    code, meaning = UNITS.get(units, ("{" + units.replace("}", "") + "}", units))
    return _coded("UCUM", code, meaning)


def unit_of(code: str) -> str:
    """volumen's unit text of a UCUM ``code`` (:func:`unit_code` backwards)."""
    back = {c: u for u, (c, _) in UNITS.items()}
    if code in back:
        return back[code]
    return code[1:-1] if code.startswith("{") and code.endswith("}") else code


def field_of(value: str, meaning: str) -> str | None:
    """The number a concept names: a key of :data:`STATISTICS` or :data:`NAMES`, None for one volumen does not
    write."""
    for table in (STATISTICS, {k: v[1:] for k, v in NAMES.items()}):
        for key, (code, _) in table.items():
            if code == value:
                return key
    return None


def tracking_text(kind: str, number: int, label: str) -> str:
    """The tracking identifier of measurement ``number`` of ``kind`` (``"region ellipse"``), with its label."""
    return f"{PREFIX} {kind} {number}" + (f": {label}" if label else "")


def parse_tracking(text: str) -> tuple[list[str], str]:
    """``(words of the kind, label)`` of a :func:`tracking_text`; another writer's identifier has no kind words and
    is kept whole as the label."""
    head, _, label = (text or "").partition(": ")
    words = head.split()
    if len(words) >= 3 and words[0] == PREFIX and words[-1].isdigit():
        return words[1:-1], label
    return [], text or ""
