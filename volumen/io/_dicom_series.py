"""DICOM headers -> series: find the image files, group them by series, read each slice's geometry.

Only headers are read here (``pydicom.dcmread(..., stop_before_pixels=True)``);
pixels are read by :mod:`volumen.io._dicom_pixels` for the chosen series only, and
the slices are ordered by :mod:`volumen.io._dicom_geometry`. Nothing read here that
identifies the patient is kept: a :class:`SliceHeader` holds geometry and rescale
numbers, a :class:`SeriesHeaders` technical facts only. A file whose header cannot be
read is recorded (path and cause) and the others go on.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pydicom
from pydicom.errors import InvalidDicomError
from pydicom.multival import MultiValue

from ..errors import CorruptDataError, VolumeReadError
from ._header_limits import open_bounded

__all__ = ["SliceHeader", "SeriesHeaders", "read_headers", "DICOM_SUFFIXES", "PIXEL_TAGS"]

DICOM_SUFFIXES = (".dcm", ".dicom", ".ima")
#: the elements that may hold an image's pixels (integer, 32-bit float, 64-bit float)
PIXEL_TAGS = ("PixelData", "FloatPixelData", "DoubleFloatPixelData")
_DICOMDIR_CLASS = "1.2.840.10008.1.3.10"
#: where a missing PixelSpacing is taken from, in this order (detector-plane spacings, with a note)
_SPACING_FALLBACKS = ("ImagerPixelSpacing", "ImagePlanePixelSpacing", "NominalScannedPixelSpacing")


@dataclass(frozen=True)
class SliceHeader:
    """One 2-D image: a single-frame file, or frame ``frame`` of a multi-frame file.

    Positions and cosines are LPS+ as in the file; ``pixel_spacing`` is
    ``(row spacing, column spacing)`` = ``(dy, dx)`` in mm.
    """

    path: str
    frame: int | None
    shape: tuple[int, int]                       # (rows, columns)
    position: tuple[float, float, float] | None  # ImagePositionPatient, mm
    orientation: tuple[float, ...] | None        # ImageOrientationPatient (6,)
    pixel_spacing: tuple[float, float] | None
    slope: float
    intercept: float
    thickness: float | None
    position_assumed: bool = False
    notes: tuple[str, ...] = ()                  # how missing or odd header values were replaced

    def label(self) -> str:
        """The file (and frame) for messages."""
        return self.path if self.frame is None else f"{self.path} (frame {self.frame + 1})"


@dataclass
class SeriesHeaders:
    """The slices of one SeriesInstanceUID and technical facts from its first file (no identity)."""

    uid: str
    description: str
    info: dict
    slices: list[SliceHeader] = field(default_factory=list)
    files: list[str] = field(default_factory=list)
    bad: list[tuple[str, str]] = field(default_factory=list)  # (path, problem) of its unreadable files


def _floats(value, n: int, path, tag: str) -> tuple[float, ...] | None:
    if value is None or value == "":
        return None
    try:
        out = tuple(float(v) for v in _as_list(value))
    except (TypeError, ValueError) as exc:
        raise CorruptDataError(path, f"{tag} is not a list of numbers ({exc})") from None
    if len(out) != n or not all(np.isfinite(out)):
        raise CorruptDataError(path, f"{tag} should hold {n} finite numbers, it holds {len(out)}")
    return out


def _float(value, default, path, tag: str) -> float | None:
    if value is None or value == "":
        return default
    try:
        return float(value)
    except (TypeError, ValueError):
        raise CorruptDataError(path, f"{tag} is not a number") from None


def _item(ds, seq: str, per_frame=None):
    """First item of functional group ``seq`` for a frame (per-frame first, then shared)."""
    for holder in (per_frame, (ds.get("SharedFunctionalGroupsSequence") or [None])[0]):
        if holder is not None and seq in holder and len(holder[seq].value):
            return holder[seq].value[0]
    return None


def _pixel_spacing(holder, ds, path) -> tuple[tuple[float, float] | None, tuple[str, ...]]:
    """``(dy, dx)`` mm and notes: PixelSpacing (of ``holder``, a functional group item, or the
    dataset), else a detector-plane spacing; ``None`` with a note when none is usable."""
    for source in (holder, ds):
        if source is not None and source.get("PixelSpacing") not in (None, ""):
            tag, value = "PixelSpacing", source.get("PixelSpacing")
            break
    else:
        tag, value = next(((t, ds.get(t)) for t in _SPACING_FALLBACKS if ds.get(t) not in (None, "")), ("", None))
    if value is None:
        return None, ()
    sp = _floats(value, 2, path, tag)
    if min(sp) <= 0:
        return None, (f"{tag} {sp[0]:g} x {sp[1]:g} mm is not positive: assumed 1 mm x 1 mm pixels",)
    if tag != "PixelSpacing":
        return sp, (f"no PixelSpacing: pixel spacing {sp[0]:g} x {sp[1]:g} mm taken from {tag} (the detector "
                    "plane; sizes in the patient may differ by the geometric magnification)",)
    return sp, ()


def _enhanced_slices(ds, path: str, shape, n_frames: int, per_frame) -> list[SliceHeader]:
    """Slices of an enhanced multi-frame file: geometry per frame from its functional groups."""
    notes: tuple[str, ...] = ()
    if len(per_frame) < n_frames:
        raise CorruptDataError(path, f"NumberOfFrames is {n_frames} but PerFrameFunctionalGroupsSequence "
                                     f"has only {len(per_frame)} items")
    if len(per_frame) > n_frames:
        notes = (f"{path}: PerFrameFunctionalGroupsSequence has {len(per_frame)} items for {n_frames} frame(s): "
                 "the first ones were used",)
    out = []
    for f, group in enumerate(list(per_frame)[:n_frames]):
        pos, ori = _item(ds, "PlanePositionSequence", group), _item(ds, "PlaneOrientationSequence", group)
        meas, pvt = _item(ds, "PixelMeasuresSequence", group), _item(ds, "PixelValueTransformationSequence", group)
        spacing, sp_notes = _pixel_spacing(meas, ds, path)
        out.append(SliceHeader(
            path, f, shape,
            _floats(pos.get("ImagePositionPatient") if pos else None, 3, path, "ImagePositionPatient"),
            _floats(ori.get("ImageOrientationPatient") if ori else None, 6, path, "ImageOrientationPatient"),
            spacing,
            _float(pvt.get("RescaleSlope") if pvt else None, 1.0, path, "RescaleSlope"),
            _float(pvt.get("RescaleIntercept") if pvt else None, 0.0, path, "RescaleIntercept"),
            _float(meas.get("SliceThickness") if meas else None, None, path, "SliceThickness"),
            notes=notes + sp_notes))
    return out


def _legacy_offsets(ds, path: str, n_frames: int, thickness) -> tuple[list[float], tuple[str, ...]]:
    """Frame offsets (mm along the normal, first 0) of a legacy multi-frame file, and how they were found."""
    offsets = ds.get("GridFrameOffsetVector")
    if offsets not in (None, ""):
        offsets = _floats(offsets, n_frames, path, "GridFrameOffsetVector")
        # relative (first is 0) or absolute (first is the position's z): frame 0 lies at ImagePositionPatient
        return [v - offsets[0] for v in offsets], ()
    between = _float(ds.get("SpacingBetweenSlices"), None, path, "SpacingBetweenSlices")
    source, step = next(((name, v) for name, v in (("SpacingBetweenSlices", between), ("SliceThickness", thickness))
                         if v is not None and v > 0), ("no SpacingBetweenSlices or SliceThickness", 1.0))
    note = (f"multi-frame file without per-frame positions: its {n_frames} frames assumed evenly spaced "
            f"{step:g} mm apart ({source})")
    return [f * step for f in range(n_frames)], (note,)


def _slices_of(ds, path: str) -> list[SliceHeader]:
    try:
        rows, cols = int(ds.Rows), int(ds.Columns)
        n_frames = int(ds.get("NumberOfFrames", 1) or 1)
    except (TypeError, ValueError):
        raise CorruptDataError(path, "Rows, Columns or NumberOfFrames is not a whole number") from None
    if n_frames > max(Path(path).stat().st_size, 1):  # every frame takes at least a byte
        raise CorruptDataError(path, f"NumberOfFrames {n_frames} is more than the file has bytes")
    if rows < 1 or cols < 1 or n_frames < 1:
        raise CorruptDataError(path, f"image size {cols} x {rows} x {n_frames} frames (columns x rows) is empty")
    per_frame = ds.get("PerFrameFunctionalGroupsSequence")
    if per_frame:
        return _enhanced_slices(ds, path, (rows, cols), n_frames, per_frame)
    spacing, notes = _pixel_spacing(None, ds, path)
    common = dict(
        shape=(rows, cols),
        orientation=_floats(ds.get("ImageOrientationPatient"), 6, path, "ImageOrientationPatient"),
        pixel_spacing=spacing,
        slope=_float(ds.get("RescaleSlope", ds.get("DoseGridScaling")), 1.0, path, "RescaleSlope"),
        intercept=_float(ds.get("RescaleIntercept"), 0.0, path, "RescaleIntercept"),
        thickness=_float(ds.get("SliceThickness"), None, path, "SliceThickness"))
    if "ModalityLUTSequence" in ds:  # the LUT replaces the linear rescale (applied with the pixels)
        common.update(slope=1.0, intercept=0.0)
    position = _floats(ds.get("ImagePositionPatient"), 3, path, "ImagePositionPatient")
    if n_frames == 1:
        return [SliceHeader(path, None, position=position, notes=notes, **common)]
    # legacy multi-frame: frames are parallel slices starting at ImagePositionPatient
    offsets, how = _legacy_offsets(ds, path, n_frames, common["thickness"])
    if position is None or common["orientation"] is None:
        notes += ("multi-frame file without ImagePositionPatient / ImageOrientationPatient: assumed axial "
                  "frames starting at the origin",)
        position = position or (0.0, 0.0, 0.0)
        common["orientation"] = common["orientation"] or (1.0, 0.0, 0.0, 0.0, 1.0, 0.0)
    o = np.asarray(common["orientation"])
    normal = np.cross(o[:3], o[3:])
    return [SliceHeader(path, f, position=tuple(np.asarray(position) + off * normal), position_assumed=bool(how),
                        notes=notes + how, **common) for f, off in enumerate(offsets)]


def _as_list(value) -> list:
    if value is None or value == "":
        return []
    return list(value) if isinstance(value, (list, tuple, MultiValue)) else [value]


def _window_presets(voi) -> list[dict]:
    if voi is None or "WindowCenter" not in voi or "WindowWidth" not in voi:
        return []
    centers, widths, names = (_as_list(voi.get(k)) for k in ("WindowCenter", "WindowWidth",
                                                              "WindowCenterWidthExplanation"))
    try:
        return [{"center": float(c), "width": float(w), "name": str(names[i]) if i < len(names) else ""}
                for i, (c, w) in enumerate(zip(centers, widths, strict=False))]
    except (TypeError, ValueError):
        return []  # unusable presets are not worth failing a load


def _uid_name(uid) -> str:
    """The registered name of a UID, or the UID itself; ``""`` when empty (some files hold an empty string)."""
    text = str(uid or "").strip()
    return pydicom.uid.UID(text).name if text else ""


def _info(ds) -> dict:
    """Technical, non-identifying facts of a series (from its first file)."""
    ts = getattr(ds.get("file_meta", None), "TransferSyntaxUID", None)
    pvt, voi = None, ds
    if "PerFrameFunctionalGroupsSequence" in ds or "SharedFunctionalGroupsSequence" in ds:
        first = (ds.get("PerFrameFunctionalGroupsSequence") or [None])[0]
        pvt = _item(ds, "PixelValueTransformationSequence", first)
        voi = _item(ds, "FrameVOILUTSequence", first)
    modality_lut = (ds.get("ModalityLUTSequence") or [None])[0]
    voi_lut = (ds.get("VOILUTSequence") or [None])[0]
    sop = ds.get("SOPClassUID") or getattr(ds.get("file_meta"), "MediaStorageSOPClassUID", "")
    try:
        samples = int(ds.get("SamplesPerPixel", 1) or 1)
    except (TypeError, ValueError):
        samples = 1
    return {
        "modality": str(ds.get("Modality", "") or "OT"),
        "series_number": str(ds.get("SeriesNumber", "") or ""),
        "manufacturer": str(ds.get("Manufacturer", "") or ""),
        "manufacturer_model": str(ds.get("ManufacturerModelName", "") or ""),
        "sop_class": _uid_name(sop),
        "sop_class_uid": str(sop or "").strip(),
        "transfer_syntax": _uid_name(ts),
        "transfer_syntax_uid": str(ts or "").strip(),
        "rescale_type": str((pvt or ds).get("RescaleType", "") or ds.get("DoseUnits", "") or ""),
        "samples_per_pixel": samples,
        "photometric": str(ds.get("PhotometricInterpretation", "") or "").strip().upper(),
        "window_presets": _window_presets(voi),
        "modality_lut": str(modality_lut.get("LUTExplanation", "") or "yes") if modality_lut else "",
        "voi_lut": str(voi_lut.get("LUTExplanation", "") or "yes") if voi_lut else "",
    }


def _dcmread(path: str, **kw):
    """pydicom.dcmread with reads clamped to the file's size (a damaged length cannot over-allocate)."""
    with open_bounded(path) as f:
        return pydicom.dcmread(f, **kw)


def _read_header(p: Path):
    """The dataset of ``p`` without pixels; ``None`` for a file that is not DICOM (no preamble, no suffix)."""
    path = str(p)
    with warnings.catch_warnings():  # pydicom warnings may quote element values
        warnings.simplefilter("ignore")
        try:
            return _dcmread(path, stop_before_pixels=True)
        except InvalidDicomError:
            if p.suffix.lower() not in DICOM_SUFFIXES and p.name.upper() != "DICOMDIR":
                return None
            try:
                ds = _dcmread(path, stop_before_pixels=True, force=True)
            except Exception:  # noqa: BLE001 - anything pydicom raises means "unreadable"
                ds = None
            if ds is None or ("Rows" not in ds and "SOPClassUID" not in ds):
                raise CorruptDataError(path, "has a DICOM suffix but is not a readable DICOM file") from None
            return ds
        except Exception as exc:  # noqa: BLE001
            raise CorruptDataError(path, f"is not a readable DICOM file ({type(exc).__name__})") from None


def _add_file(series: dict[str, SeriesHeaders], ds, path: str, notes: list[str], dicomdirs: list[str]) -> None:
    """File the image slices of one dataset under their series (or note why it holds none)."""
    sop = str(ds.get("SOPClassUID", "") or getattr(ds.get("file_meta", None), "MediaStorageSOPClassUID", "") or "")
    if sop.strip() == _DICOMDIR_CLASS or "DirectoryRecordSequence" in ds:
        dicomdirs.append(path)
        return
    if "Rows" not in ds or "Columns" not in ds:
        kind = _uid_name(sop) or "unknown SOP class"
        if "Image Storage" in kind:
            raise CorruptDataError(path, f"is a {kind} file without image size or pixel data (truncated?)")
        notes.append(f"skipped {path}: DICOM file without pixel data ({kind})")
        return
    slices = _slices_of(ds, path)
    uid = str(ds.get("SeriesInstanceUID", "") or "").strip() or "(no SeriesInstanceUID)"
    if uid not in series:
        series[uid] = SeriesHeaders(uid, str(ds.get("SeriesDescription", "") or ""), _info(ds))
    series[uid].slices.extend(slices)
    series[uid].files.append(path)


def _series_uid(ds) -> str:
    """SeriesInstanceUID of a dataset whose other values may be broken; ``""`` when unknown."""
    try:
        return str(ds.get("SeriesInstanceUID", "") or "").strip() if ds is not None else ""
    except Exception:  # noqa: BLE001 - a broken element: the series is unknown
        return ""


def read_headers(paths: list[Path], notes: list[str], dicomdirs: list[str],
                 bad: list[tuple[str, str, str]] | None = None) -> dict[str, SeriesHeaders]:
    """Read the headers of ``paths`` and group the image slices by SeriesInstanceUID.

    Files that are not DICOM (no ``DICM`` preamble and no DICOM suffix) and DICOMDIR
    files are skipped silently (DICOMDIRs listed in ``dicomdirs``); DICOM files without
    image data get a line in ``notes``. A DICOM file whose header cannot be read is
    appended to ``bad`` as ``(path, problem, SeriesInstanceUID or "")`` and the others go
    on; with ``bad=None`` it raises :class:`CorruptDataError` instead.
    """
    series: dict[str, SeriesHeaders] = {}
    for p in paths:
        ds = None
        try:
            with warnings.catch_warnings():  # pydicom converts values lazily; its warnings may quote them
                warnings.simplefilter("ignore")
                ds = _read_header(p)
                if ds is not None:
                    _add_file(series, ds, str(p), notes, dicomdirs)
        except Exception as exc:  # noqa: BLE001 - typed errors, or a header value pydicom cannot convert
            typed = exc if isinstance(exc, VolumeReadError) else CorruptDataError(
                p, f"has an unreadable header ({type(exc).__name__})")
            if bad is None:
                raise typed from None
            bad.append((str(p), typed.problem, _series_uid(ds)))
    return series
