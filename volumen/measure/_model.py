"""The measurements, independent of any viewer: points, distances, angles, regions with statistics and structure
volumes, each in world millimetres (RAS+, docs/design.md section 2) and each remembering the scan it was made on.

Every measurement is a frozen dataclass with ``to_dict`` (JSON), ``row`` (a table row, :mod:`._table`) and
``_repr_html_`` (a one-row table in Jupyter); :class:`Measurements` is a list of them that shows as one table.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..core import mm_text, value_text
from ._plane_shapes import Plane, shape_from_dict
from ._table import csv_text, html_table

__all__ = ["Scan", "Point", "Distance", "Angle", "RegionStats", "LabelVolume", "Measurements", "from_dict", "KINDS"]


@dataclass(frozen=True)
class Scan:
    """The scan a measurement was made on: its DICOM series and frame of reference where it has them, else the
    file it was read from (or a phantom's name)."""

    series_uid: str = ""
    source: str = ""
    frame_uid: str = ""

    @classmethod
    def of(cls, volume) -> Scan:
        """The scan of ``volume`` (``meta``'s ``series_uid``, ``source`` and ``frame_of_reference_uid``)."""
        if volume is None:
            return cls()
        meta = getattr(volume, "meta", {}) or {}
        src = meta.get("source", "") or getattr(volume, "name", "")
        src = src[0] if isinstance(src, list) and len(src) == 1 else src
        return cls(str(meta.get("series_uid", "") or ""), str(src), str(meta.get("frame_of_reference_uid", "") or ""))

    def matches(self, other: Scan) -> bool:
        """Whether ``other`` names the same scan: the same series where both have one, else the same source; a
        scan that names nothing (a measurement made without a volume) matches any."""
        if not (self.series_uid or self.source) or not (other.series_uid or other.source):
            return True
        if self.series_uid and other.series_uid:
            return self.series_uid == other.series_uid
        return self.source == other.source

    def text(self) -> str:
        return self.series_uid or self.source

    def to_dict(self) -> dict:
        return {"series_uid": self.series_uid, "source": self.source, "frame_uid": self.frame_uid}


def _xyz(p) -> tuple[float, float, float]:
    a = np.asarray(p, dtype=float).reshape(-1)
    if a.shape != (3,) or not np.all(np.isfinite(a)):
        raise ValueError(f"a point is three finite world coordinates (x, y, z) in mm, got {np.asarray(p).tolist()}")
    return tuple(a.tolist())


def _points_text(points) -> str:
    return " ; ".join(" ".join(mm_text(c) for c in p) for p in points)


class _Shown:
    """What every measurement shares: its table row as HTML in Jupyter."""

    def _repr_html_(self) -> str:
        return html_table([self.row()])


@dataclass(frozen=True)
class Point(_Shown):
    """A point in world RAS+ mm."""

    position: tuple[float, float, float]
    scan: Scan = field(default_factory=Scan)
    label: str = ""
    kind = "point"

    def __post_init__(self):
        object.__setattr__(self, "position", _xyz(self.position))

    @property
    def points(self) -> tuple:
        return (self.position,)

    def row(self) -> dict:
        return {"kind": self.kind, "label": self.label, "points_mm": _points_text(self.points),
                "scan": self.scan.text()}


@dataclass(frozen=True)
class Distance(_Shown):
    """A ruler from ``start`` to ``end`` (world RAS+ mm); ``mm`` is its length."""

    start: tuple[float, float, float]
    end: tuple[float, float, float]
    scan: Scan = field(default_factory=Scan)
    label: str = ""
    kind = "distance"

    def __post_init__(self):
        object.__setattr__(self, "start", _xyz(self.start))
        object.__setattr__(self, "end", _xyz(self.end))

    @property
    def points(self) -> tuple:
        return (self.start, self.end)

    @property
    def mm(self) -> float:
        return float(np.linalg.norm(np.subtract(self.end, self.start)))

    def row(self) -> dict:
        return {"kind": self.kind, "label": self.label, "value": mm_text(self.mm), "unit": "mm",
                "points_mm": _points_text(self.points), "scan": self.scan.text()}


@dataclass(frozen=True)
class Angle(_Shown):
    """The angle at ``vertex`` between the rays to ``first`` and ``second`` (world RAS+ mm); ``degrees`` 0..180."""

    first: tuple[float, float, float]
    vertex: tuple[float, float, float]
    second: tuple[float, float, float]
    scan: Scan = field(default_factory=Scan)
    label: str = ""
    kind = "angle"

    def __post_init__(self):
        for name in ("first", "vertex", "second"):
            object.__setattr__(self, name, _xyz(getattr(self, name)))
        if np.allclose(self.first, self.vertex) or np.allclose(self.second, self.vertex):
            raise ValueError("an angle needs its two arms to leave the vertex: a point equals the vertex")

    @property
    def points(self) -> tuple:
        return (self.first, self.vertex, self.second)

    @property
    def degrees(self) -> float:
        a = np.subtract(self.first, self.vertex)
        b = np.subtract(self.second, self.vertex)
        return float(np.degrees(np.arctan2(np.linalg.norm(np.cross(a, b)), np.dot(a, b))))

    def row(self) -> dict:
        return {"kind": self.kind, "label": self.label, "value": f"{self.degrees:.1f}", "unit": "deg",
                "points_mm": _points_text(self.points), "scan": self.scan.text()}


@dataclass(frozen=True)
class RegionStats(_Shown):
    """A region on a slice plane with the statistics of the scan's voxels inside it (:func:`roi_stats`).

    ``mean``, ``sd`` (population), ``min``, ``max``, ``median`` are in ``units`` (HU for a CT); ``area_mm2`` is the
    shape's area on the plane; ``voxels`` how many voxels the statistics cover.
    """

    plane: Plane
    shape: object
    mean: float
    sd: float
    min: float
    max: float
    median: float
    area_mm2: float
    voxels: int
    units: str = ""
    scan: Scan = field(default_factory=Scan)
    label: str = ""
    kind = "region"

    @property
    def points(self) -> tuple:
        """The shape's outline in world mm (an ellipse: the ends of its axes)."""
        return tuple(map(tuple, self.plane.to_world(self.shape.outline()).tolist()))

    def row(self) -> dict:
        v = {"units": self.units}
        return {"kind": f"{self.kind} ({self.shape.kind})", "label": self.label, "mean": value_text(self.mean, **v),
                "sd": value_text(self.sd, **v), "min": value_text(self.min, **v), "max": value_text(self.max, **v),
                "median": value_text(self.median, **v), "area_mm2": f"{self.area_mm2:.1f}", "voxels": self.voxels,
                "values_unit": self.units, "points_mm": _points_text(self.points), "plane": _plane_text(self.plane),
                "scan": self.scan.text()}


def _plane_text(plane: Plane) -> str:
    n = plane.normal
    return f"origin {' '.join(mm_text(c) for c in plane.origin)} normal {' '.join(f'{c:.3f}' for c in n)}"


@dataclass(frozen=True)
class LabelVolume(_Shown):
    """The volume of structure ``value`` (named ``label``) of a label map: ``voxels`` and ``ml``."""

    value: int
    label: str
    voxels: int
    ml: float
    scan: Scan = field(default_factory=Scan)
    kind = "volume"

    def row(self) -> dict:
        return {"kind": self.kind, "label": self.label or str(self.value), "value": f"{self.ml:.2f}", "unit": "ml",
                "voxels": self.voxels, "scan": self.scan.text()}


KINDS = {c.kind: c for c in (Point, Distance, Angle, RegionStats, LabelVolume)}


def _to_dict(m) -> dict:
    """A measurement as JSON-ready data (its kind, fields and scan)."""
    d = {"kind": m.kind}
    for name in m.__dataclass_fields__:
        value = getattr(m, name)
        d[name] = value.to_dict() if hasattr(value, "to_dict") else (list(value) if isinstance(value, tuple) else value)
    return d


def from_dict(d: dict):
    """The measurement a :meth:`Measurements.to_dicts` entry describes."""
    from ..errors import UnknownChoiceError

    kind = d.get("kind")
    if kind not in KINDS:
        raise UnknownChoiceError("measurement kind", kind, tuple(KINDS))
    fields = {k: v for k, v in d.items() if k != "kind"}
    fields["scan"] = Scan(**fields.get("scan", {}))
    if kind == "region":
        fields["plane"] = Plane.from_dict(fields["plane"])
        fields["shape"] = shape_from_dict(fields["shape"])
    return KINDS[kind](**fields)


class Measurements(list):
    """A list of measurements that shows as one table in Jupyter and writes JSON-ready dicts and CSV."""

    def rows(self) -> list[dict]:
        return [m.row() for m in self]

    def _repr_html_(self) -> str:
        return html_table(self.rows())

    def to_csv(self) -> str:
        return csv_text(self.rows())

    def to_dicts(self) -> list[dict]:
        return [_to_dict(m) for m in self]

    @classmethod
    def from_dicts(cls, items) -> Measurements:
        return cls(from_dict(d) for d in items)
