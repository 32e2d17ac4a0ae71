"""Measurements read back from a DICOM SR (TID 1500) with highdicom: volumen's own (:mod:`._sr_write`) whole, and
another writer's rulers, angles, points and regions as far as their coordinates and numbers tell.

A region's plane is rebuilt from its outline (the plane is not in the SR): for a rectangle its first corner and
edges, for an ellipse its centre and axes, for a polygon its first point and the outline's normal; its world
points, statistics and area are the SR's.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import MeasurementError
from ._model import Angle, Distance, LabelVolume, Measurements, Point, RegionStats, Scan
from ._plane_shapes import Ellipse, Plane, Polygon, Rectangle
from ._sr_codes import LPS, field_of, parse_tracking, unit_of

__all__ = ["read_sr", "SRFacts"]


@dataclass(frozen=True)
class SRFacts:
    """What an SR says about where its measurements belong."""

    study_uid: str
    series_uids: tuple[str, ...]
    frame_uid: str


def _numbers(group) -> dict:
    """``{field: (value, units)}`` of a group's measurements volumen knows by name."""
    found = {}
    for m in group.get_measurements():
        key = field_of(str(m.name.value), str(m.name.meaning))
        if key is not None:
            found[key] = (float(m.value), unit_of(str(m.unit.value)))
    return found


def _region(points: np.ndarray, graphic: str, words: list[str], numbers: dict, scan: Scan, label: str) -> RegionStats:
    if graphic == "ELLIPSE":
        centre = points.mean(axis=0)
        a, b = np.linalg.norm(points[1] - points[0]) / 2, np.linalg.norm(points[3] - points[2]) / 2
        plane, shape = Plane(tuple(centre), points[1] - points[0], points[3] - points[2]), Ellipse((0.0, 0.0), (a, b))
    else:
        pts = points[:-1] if np.allclose(points[0], points[-1]) else points
        normal = np.sum(np.cross(pts - pts.mean(0), np.roll(pts, -1, axis=0) - pts.mean(0)), axis=0)  # Newell
        u = pts[1] - pts[0]
        plane = Plane(tuple(pts[0]), u, np.cross(normal, u))
        st, _ = plane.to_plane(pts)
        is_rect = "rectangle" in words and len(st) == 4
        shape = Rectangle(tuple(st[0]), tuple(st[2])) if is_rect else Polygon(tuple(map(tuple, st)))
    units = numbers.get("mean", (0.0, ""))[1]
    stats = {f: numbers.get(f, (float("nan"), ""))[0] for f in ("mean", "sd", "min", "max", "median", "area_mm2")}
    return RegionStats(plane=plane, shape=shape, voxels=int(numbers.get("voxels", (0, ""))[0]), units=units, scan=scan,
                  label=label, **stats)


def _planar(group, scan: Scan):
    words, label = parse_tracking(str(group.tracking_identifier or ""))
    roi = group.roi
    if roi is None or not hasattr(roi, "frame_of_reference_uid"):
        return None  # a region on one image in pixels (SCOORD), not in the frame of reference
    points = np.asarray(roi.value, float).reshape(-1, 3) * LPS
    graphic = roi.graphic_type.value
    numbers = _numbers(group)
    if graphic == "POINT":
        return Point(points[0], scan=scan, label=label)
    if graphic in ("POLYLINE", "MULTIPOINT") and len(points) == 2:
        return Distance(points[0], points[1], scan=scan, label=label)
    if graphic in ("POLYLINE", "MULTIPOINT") and len(points) == 3 and "region" not in words:
        return Angle(points[0], points[1], points[2], scan=scan, label=label)
    if graphic in ("ELLIPSE", "POLYGON", "POLYLINE"):
        return _region(points, graphic, words, numbers, scan, label)
    return None


def _volume(group, scan: Scan):
    words, label = parse_tracking(str(group.tracking_identifier or ""))
    numbers = _numbers(group)
    if "volume" not in numbers:
        return None
    value = int(words[1]) if len(words) == 2 and words[1].isdigit() else 0
    return LabelVolume(value=value, label=label, voxels=int(numbers.get("voxels", (0, ""))[0]),
                       ml=numbers["volume"][0], scan=scan)


def _order(group) -> int:
    text = str(group.tracking_identifier or "").partition(": ")[0].split()
    return int(text[-1]) if text and text[-1].isdigit() else 0


def read_sr(path) -> tuple[Measurements, SRFacts]:
    """The measurements of the SR at ``path`` and the study, series and frame of reference they belong to.

    Raises
    ------
    MeasurementError
        The file is no SR with a measurement report.
    """
    import highdicom as hd
    import pydicom

    try:
        sr = hd.sr.srread(path)
    except (pydicom.errors.InvalidDicomError, ValueError, AttributeError, TypeError) as exc:
        raise MeasurementError(f"{path}: not a DICOM SR measurement report ({exc})") from None
    report = sr.content
    if not isinstance(report, hd.sr.MeasurementReport):
        raise MeasurementError(f"{path}: the SR holds no TID 1500 measurement report")
    evidence = sr.get("CurrentRequestedProcedureEvidenceSequence", [])
    series = tuple(str(s.SeriesInstanceUID) for study in evidence for s in study.ReferencedSeriesSequence)
    planar = report.get_planar_roi_measurement_groups()
    frames = {g.roi.frame_of_reference_uid for g in planar if hasattr(g.roi, "frame_of_reference_uid")}
    scan = Scan(series_uid=series[0] if len(series) == 1 else "", frame_uid=next(iter(frames), ""))
    found = [(_order(g), _planar(g, scan)) for g in planar]
    found += [(_order(g), _volume(g, scan)) for g in report.get_image_measurement_groups()]
    items = Measurements(m for _, m in sorted((p for p in found if p[1] is not None), key=lambda p: p[0]))
    return items, SRFacts(str(sr.StudyInstanceUID), series, scan.frame_uid)
