"""Measurements as a DICOM Comprehensive 3D SR: a TID 1500 measurement report made with highdicom, in the scan's
study, its evidence every instance of the scan's series.

Each point, ruler, angle and region is a planar ROI group (TID 1410) whose region is 3-D coordinates (SCOORD3D,
LPS+ mm in the scan's frame of reference): a point a POINT, a ruler a two-point POLYLINE with its Length (mm), an
angle a three-point POLYLINE with its Angle (deg), a region a POLYGON (closed) or an ELLIPSE (the ends of its axes)
with its Mean, Standard Deviation, Minimum, Maximum, Median (the scan's units: HU as UCUM ``[hnsf'U]``), Area
(mm2) and voxel Count; each number references the images of the slices the measurement lies in. A structure's
volume is a measurement group without a region (TID 1501), Volume in ml. The kind and label of each travel in its
tracking identifier (:mod:`._sr_codes`).
"""

from __future__ import annotations

import numpy as np

from ..errors import LabelError, MeasurementError
from ._model import Measurements
from ._persistence import check_scan
from ._sr_codes import LPS, STATISTICS, name_code, tracking_text, unit_code

__all__ = ["make_sr"]


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("volumen")
    except PackageNotFoundError:
        return "unknown"


def _number(hd, field: str, value: float, units: str, images=None):
    return hd.sr.Measurement(name=name_code(field), value=float(value), unit=unit_code(units),
                             referenced_images=images or None)


def _images(hd, m, volume, sources) -> list:
    """The scan's images a measurement was made on: those of the slices its points lie in (``sources`` sorted
    like the volume's slices)."""
    k = np.rint(volume.world_to_index(np.asarray(m.points, float))[:, 2]).astype(int)
    return [hd.sr.SourceImageForMeasurement.from_source_image(sources[i])
            for i in sorted(set(np.clip(k, 0, len(sources) - 1).tolist()))]


def _region_3d(hd, m, frame_uid: str):
    """The SCOORD3D of a measurement's points (LPS+), by kind."""
    pts = np.asarray(m.points, float) * LPS
    if m.kind == "point":
        kind = hd.sr.GraphicTypeValues3D.POINT
    elif m.kind in ("distance", "angle"):
        kind = hd.sr.GraphicTypeValues3D.POLYLINE
    elif m.shape.kind == "ellipse":
        kind = hd.sr.GraphicTypeValues3D.ELLIPSE
    else:
        kind = hd.sr.GraphicTypeValues3D.POLYGON
        pts = np.vstack([pts, pts[:1]])  # DICOM closes a polygon by repeating its first point
    return hd.sr.ImageRegion3D(graphic_type=kind, graphic_data=pts, frame_of_reference_uid=frame_uid)


def _numbers(hd, m, images) -> list:
    if m.kind == "distance":
        return [_number(hd, "length", m.mm, "mm", images)]
    if m.kind == "angle":
        return [_number(hd, "angle", m.degrees, "deg", images)]
    if m.kind == "region":
        found = [_number(hd, f, getattr(m, f), "mm2" if f == "area_mm2" else m.units, images) for f in STATISTICS]
        return [*found, _number(hd, "voxels", m.voxels, "voxels", images)]
    return []


def _group(hd, m, number: int, frame_uid: str, images: list):
    kind = {"region": f"region {getattr(m, 'shape', None) and m.shape.kind}",
            "volume": f"volume {getattr(m, 'value', '')}"}.get(m.kind, m.kind)
    tracking = hd.sr.TrackingIdentifier(uid=hd.UID(), identifier=tracking_text(kind, number, m.label))
    if m.kind == "volume":
        numbers = [_number(hd, "volume", m.ml, "ml"), _number(hd, "voxels", m.voxels, "voxels")]
        return hd.sr.MeasurementsAndQualitativeEvaluations(tracking_identifier=tracking, measurements=numbers)
    return hd.sr.PlanarROIMeasurementsAndQualitativeEvaluations(
        tracking_identifier=tracking, referenced_region=_region_3d(hd, m, frame_uid),
        measurements=_numbers(hd, m, images))


def _sources(volume) -> list:
    from ..pacs import source_images

    try:
        return source_images(volume)
    except LabelError as exc:
        raise MeasurementError(f"an SR references the scan's DICOM images: {exc.problem}") from None


def make_sr(items, volume, *, description: str = "volumen measurements"):
    """A Comprehensive 3D SR (TID 1500) of ``items`` (measurements made on ``volume``, a scan read from DICOM).

    Returns
    -------
    highdicom.sr.Comprehensive3DSR
        A new series in the scan's study, ready for ``save_as`` or :func:`volumen.pacs.send`.

    Raises
    ------
    MeasurementError
        A measurement made on another scan; a scan not read from DICOM files; nothing to report.
    """
    import highdicom as hd
    from pydicom.sr.codedict import codes

    items = Measurements(items)
    if not items:
        raise MeasurementError("no measurements to write")
    check_scan(items, volume)
    sources = _sources(volume)
    frame_uid = str(sources[0].FrameOfReferenceUID)
    groups = [_group(hd, m, n, frame_uid, _images(hd, m, volume, sources) if hasattr(m, "points") else [])
              for n, m in enumerate(items, start=1)]
    device = hd.sr.ObserverContext(
        observer_type=codes.cid270.Device,
        observer_identifying_attributes=hd.sr.DeviceObserverIdentifyingAttributes(uid=hd.UID(), name="volumen"))
    report = hd.sr.MeasurementReport(
        observation_context=hd.sr.ObservationContext(observer_device_context=device),
        procedure_reported=codes.LN.CTUnspecifiedBodyRegion if volume.modality == "CT" else codes.SCT.ImagingProcedure,
        imaging_measurements=groups)
    return hd.sr.Comprehensive3DSR(
        evidence=sources, content=report[0], series_instance_uid=hd.UID(), series_number=902,
        sop_instance_uid=hd.UID(), instance_number=1, manufacturer="volumen", is_complete=True,
        series_description=description[:64], software_versions=_version())
