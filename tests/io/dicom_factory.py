"""Synthetic DICOM files for the reader's tests, written with pydicom.

Everything here is in DICOM's own terms: positions and direction cosines are in
patient LPS+ millimetres, pixel arrays are ``[slice, row, column]`` of *stored*
values (before RescaleSlope / RescaleIntercept). The tests compute what the
reader should return (RAS+ affine, physical values) on their own.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
from pydicom.dataset import Dataset, FileMetaDataset
from pydicom.encaps import encapsulate
from pydicom.sequence import Sequence as DicomSequence
from pydicom.uid import (
    PYDICOM_IMPLEMENTATION_UID,
    CTImageStorage,
    EnhancedCTImageStorage,
    ExplicitVRLittleEndian,
    generate_uid,
)

__all__ = ["rotation", "oblique_cosines", "stack_positions", "write_series", "write_enhanced",
           "write_non_image", "write_legacy_multiframe", "new_uid", "PATIENT"]

# identifying values the privacy test looks for
PATIENT = {"PatientName": "Doe^Jane", "PatientID": "SECRET123", "PatientBirthDate": "19700101",
           "PatientAddress": "1 Secret Street", "ReferringPhysicianName": "Who^Doctor",
           "InstitutionName": "Hidden Hospital", "AccessionNumber": "ACC98765"}

BASIC_TEXT_SR = "1.2.840.10008.5.1.4.1.1.88.11"


def new_uid(seed: str) -> str:
    """A deterministic UID derived from ``seed``."""
    return generate_uid(entropy_srcs=[seed])


def rotation(axis: Sequence[float], degrees: float) -> np.ndarray:
    """(3, 3) rotation matrix about ``axis`` (Rodrigues), right-handed, ``degrees``."""
    a = np.asarray(axis, float)
    a = a / np.linalg.norm(a)
    t = np.deg2rad(degrees)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + np.sin(t) * k + (1 - np.cos(t)) * (k @ k)


def oblique_cosines(axis=(1.0, 0.3, 0.0), degrees: float = 20.0) -> tuple[np.ndarray, np.ndarray]:
    """Row and column direction cosines (LPS) of an axial plane rotated about ``axis``."""
    r = rotation(axis, degrees)
    return r @ np.array([1.0, 0.0, 0.0]), r @ np.array([0.0, 1.0, 0.0])


def stack_positions(origin, row_dir, col_dir, offsets: Sequence[float]) -> np.ndarray:
    """(n, 3) LPS positions ``origin + offset * normal`` with ``normal = row_dir x col_dir``."""
    normal = np.cross(row_dir, col_dir)
    return np.asarray(origin, float)[None] + np.asarray(offsets, float)[:, None] * normal[None]


def _ds(v: float) -> str:
    return f"{float(v):.10g}"


def _file_meta(sop_class: str, sop_uid: str, transfer_syntax: str) -> FileMetaDataset:
    meta = FileMetaDataset()
    meta.MediaStorageSOPClassUID = sop_class
    meta.MediaStorageSOPInstanceUID = sop_uid
    meta.TransferSyntaxUID = transfer_syntax
    meta.ImplementationClassUID = PYDICOM_IMPLEMENTATION_UID
    return meta


def _base(sop_class: str, sop_uid: str, series_uid: str, modality: str, patient: dict | None,
          transfer_syntax: str) -> Dataset:
    ds = Dataset()
    ds.file_meta = _file_meta(sop_class, sop_uid, transfer_syntax)
    ds.SOPClassUID = sop_class
    ds.SOPInstanceUID = sop_uid
    ds.StudyInstanceUID = new_uid("study")
    ds.SeriesInstanceUID = series_uid
    ds.FrameOfReferenceUID = new_uid("frame-of-reference")
    ds.Modality = modality
    ds.Manufacturer = "volumen-tests"
    ds.StudyDate = "20240102"
    for key, value in (patient or {"PatientName": "Anonymous^", "PatientID": "0"}).items():
        setattr(ds, key, value)
    return ds


def _pixels(ds: Dataset, raw: np.ndarray) -> None:
    ds.SamplesPerPixel = 1
    ds.PhotometricInterpretation = "MONOCHROME2"
    ds.Rows, ds.Columns = int(raw.shape[-2]), int(raw.shape[-1])
    ds.BitsAllocated = raw.dtype.itemsize * 8
    ds.BitsStored = raw.dtype.itemsize * 8
    ds.HighBit = ds.BitsStored - 1
    ds.PixelRepresentation = 1 if raw.dtype.kind == "i" else 0
    ds.PixelData = np.ascontiguousarray(raw).astype(raw.dtype.newbyteorder("<")).tobytes()


def write_series(folder, raw: np.ndarray, *, row_dir, col_dir, positions, pixel_spacing=(0.8, 0.6),
                 slope=1.0, intercept=0.0, series_uid: str | None = None, description: str = "test series",
                 modality: str = "CT", patient: dict | None = None, shuffle_seed: int | None = 0,
                 prefix: str = "IM", slice_thickness: float | None = 2.5, transfer_syntax: str | None = None,
                 encapsulated: bytes | None = None, window: tuple[float, float] | None = (40.0, 400.0),
                 rescale_type: str | None = None) -> list[Path]:
    """Write one single-frame file per slice; return the paths in the order of ``raw``.

    Parameters
    ----------
    folder : path
        Created if missing.
    raw : (n, rows, cols) int16 or uint16
        Stored values, slice ``k`` written with ``positions[k]``.
    row_dir, col_dir : (3,) float
        ImageOrientationPatient halves (LPS): direction of a row (increasing column) and
        of a column (increasing row).
    positions : (n, 3) float, mm
        ImagePositionPatient of each slice (LPS).
    pixel_spacing : (row spacing, column spacing), mm
    slope, intercept : float or (n,) float
        RescaleSlope / RescaleIntercept, one for all or one per slice.
    shuffle_seed : int or None
        File names are numbered in a shuffled order (None: in slice order), so the
        directory listing says nothing about the geometry.
    transfer_syntax, encapsulated : optional
        With ``encapsulated`` bytes the PixelData is that single encapsulated frame
        under ``transfer_syntax`` (used to fake compressed files).
    """
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    n = raw.shape[0]
    series_uid = series_uid or new_uid(f"series-{folder}-{prefix}")
    slopes = np.broadcast_to(np.asarray(slope, float), (n,))
    intercepts = np.broadcast_to(np.asarray(intercept, float), (n,))
    names = np.arange(n) if shuffle_seed is None else np.random.default_rng(shuffle_seed).permutation(n)
    paths = []
    for k in range(n):
        sop_uid = new_uid(f"{series_uid}-{k}")
        ts = transfer_syntax or ExplicitVRLittleEndian
        ds = _base(CTImageStorage, sop_uid, series_uid, modality, patient, ts)
        ds.SeriesDescription = description
        ds.InstanceNumber = int(k + 1)
        ds.ImageOrientationPatient = [_ds(v) for v in (*row_dir, *col_dir)]
        ds.ImagePositionPatient = [_ds(v) for v in positions[k]]
        ds.PixelSpacing = [_ds(v) for v in pixel_spacing]
        if slice_thickness is not None:
            ds.SliceThickness = _ds(slice_thickness)
        ds.RescaleSlope = _ds(slopes[k])
        ds.RescaleIntercept = _ds(intercepts[k])
        if rescale_type:
            ds.RescaleType = rescale_type
        if window:
            ds.WindowCenter, ds.WindowWidth = _ds(window[0]), _ds(window[1])
        _pixels(ds, raw[k])
        if encapsulated is not None:
            ds.PixelData = encapsulate([encapsulated])
            ds["PixelData"].VR = "OB"
        path = folder / f"{prefix}{int(names[k]):04d}.dcm"
        ds.save_as(path, enforce_file_format=True)
        paths.append(path)
    return paths


def write_enhanced(path, raw: np.ndarray, *, row_dir, col_dir, positions, pixel_spacing=(0.8, 0.6),
                   slope=1.0, intercept=0.0, per_frame_rescale: bool = False, frame_order=None,
                   series_uid: str | None = None, description: str = "enhanced test",
                   patient: dict | None = None) -> Path:
    """Write an Enhanced CT multi-frame file: frame ``f`` holds slice ``frame_order[f]`` of ``raw``.

    Orientation and pixel spacing go into SharedFunctionalGroupsSequence; each frame's
    ImagePositionPatient into PerFrameFunctionalGroupsSequence. Rescale goes into the
    shared groups (scalars) or, with ``per_frame_rescale``, into each frame's groups
    (``slope`` / ``intercept`` may then be per slice of ``raw``).
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    n = raw.shape[0]
    order = np.arange(n) if frame_order is None else np.asarray(frame_order)
    slopes = np.broadcast_to(np.asarray(slope, float), (n,))
    intercepts = np.broadcast_to(np.asarray(intercept, float), (n,))
    series_uid = series_uid or new_uid(f"enhanced-{path}")
    ds = _base(EnhancedCTImageStorage, new_uid(f"{series_uid}-mf"), series_uid, "CT", patient,
               ExplicitVRLittleEndian)
    ds.SeriesDescription = description
    ds.InstanceNumber = 1
    ds.NumberOfFrames = n

    def rescale_item(k):
        item = Dataset()
        item.RescaleSlope, item.RescaleIntercept, item.RescaleType = _ds(slopes[k]), _ds(intercepts[k]), "HU"
        return item

    shared = Dataset()
    orient, measures = Dataset(), Dataset()
    orient.ImageOrientationPatient = [_ds(v) for v in (*row_dir, *col_dir)]
    measures.PixelSpacing = [_ds(v) for v in pixel_spacing]
    measures.SliceThickness = "1.5"
    shared.PlaneOrientationSequence = DicomSequence([orient])
    shared.PixelMeasuresSequence = DicomSequence([measures])
    if not per_frame_rescale:
        shared.PixelValueTransformationSequence = DicomSequence([rescale_item(0)])
    ds.SharedFunctionalGroupsSequence = DicomSequence([shared])
    frames = []
    for f in range(n):
        k = int(order[f])
        item, pos = Dataset(), Dataset()
        pos.ImagePositionPatient = [_ds(v) for v in positions[k]]
        item.PlanePositionSequence = DicomSequence([pos])
        if per_frame_rescale:
            item.PixelValueTransformationSequence = DicomSequence([rescale_item(k)])
        frames.append(item)
    ds.PerFrameFunctionalGroupsSequence = DicomSequence(frames)
    _pixels(ds, raw[order])
    ds.save_as(path, enforce_file_format=True)
    return path


def write_non_image(path, patient: dict | None = None) -> Path:
    """Write a Basic Text SR (a DICOM file without pixel data)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    ds = _base(BASIC_TEXT_SR, new_uid(f"sr-{path}"), new_uid(f"sr-series-{path}"), "SR", patient,
               ExplicitVRLittleEndian)
    ds.SeriesDescription = "a report"
    ds.save_as(path, enforce_file_format=True)
    return path


def write_legacy_multiframe(path, raw: np.ndarray, *, row_dir, col_dir, position, offsets=None,
                            spacing_between: float | None = None, dose_scaling: float | None = None) -> Path:
    """Write an RT-Dose-like multi-frame file: one ImagePositionPatient, frames along the normal.

    ``offsets`` (n,) mm go into GridFrameOffsetVector; without them ``spacing_between``
    goes into SpacingBetweenSlices. ``dose_scaling`` is DoseGridScaling (units GY).
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    uid = new_uid(f"legacy-{path}")
    ds = _base("1.2.840.10008.5.1.4.1.1.481.2", new_uid(f"{uid}-i"), uid, "RTDOSE", None, ExplicitVRLittleEndian)
    ds.NumberOfFrames = raw.shape[0]
    ds.ImageOrientationPatient = [_ds(v) for v in (*row_dir, *col_dir)]
    ds.ImagePositionPatient = [_ds(v) for v in position]
    ds.PixelSpacing = ["2.5", "2"]
    if offsets is not None:
        ds.GridFrameOffsetVector = [_ds(v) for v in offsets]
    if spacing_between is not None:
        ds.SpacingBetweenSlices = _ds(spacing_between)
    if dose_scaling is not None:
        ds.DoseGridScaling = _ds(dose_scaling)
        ds.DoseUnits = "GY"
    _pixels(ds, raw)
    ds.save_as(path, enforce_file_format=True)
    return path
