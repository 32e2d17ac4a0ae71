"""DICOM headers -> series: find the image files, group them, order the slices, build the geometry.

Only headers are read here (``pydicom.dcmread(..., stop_before_pixels=True)``);
pixels are read by :mod:`volumen.io._dicom` for the chosen series only.

Geometry is computed in DICOM's patient LPS+ space and turned into RAS+ once,
in :func:`measure`, by negating the x and y rows of the affine. Nothing read
here that identifies the patient is kept: a :class:`SliceHeader` holds geometry
and rescale numbers, a :class:`SeriesHeaders` technical facts only.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
import pydicom
from pydicom.errors import InvalidDicomError
from pydicom.multival import MultiValue

from ..errors import CorruptDataError, SeriesError

__all__ = ["SliceHeader", "SeriesHeaders", "Geometry", "read_headers", "measure", "DICOM_SUFFIXES"]

DICOM_SUFFIXES = (".dcm", ".dicom", ".ima")
_DICOMDIR_CLASS = "1.2.840.10008.1.3.10"
_LPS_TO_RAS = np.diag([-1.0, -1.0, 1.0, 1.0])
_SAME_ORIENTATION = 1e-4     # max difference of direction cosines within one series
_DUPLICATE_MM = 1e-3         # slices closer than this along the normal share a position
_UNIFORM_MM, _UNIFORM_REL = 0.01, 0.01  # a gap may differ from the mean by max(0.01 mm, 1 %)


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


def _slices_of(ds, path: str) -> list[SliceHeader]:
    try:
        rows, cols = int(ds.Rows), int(ds.Columns)
        n_frames = int(ds.get("NumberOfFrames", 1) or 1)
    except (TypeError, ValueError):
        raise CorruptDataError(path, "Rows, Columns or NumberOfFrames is not a whole number") from None
    per_frame = ds.get("PerFrameFunctionalGroupsSequence")
    if per_frame is not None:
        if len(per_frame) != n_frames:
            raise CorruptDataError(path, f"NumberOfFrames is {n_frames} but PerFrameFunctionalGroupsSequence "
                                         f"has {len(per_frame)} items")
        out = []
        for f, group in enumerate(per_frame):
            pos, ori = _item(ds, "PlanePositionSequence", group), _item(ds, "PlaneOrientationSequence", group)
            meas, pvt = _item(ds, "PixelMeasuresSequence", group), _item(ds, "PixelValueTransformationSequence", group)
            out.append(SliceHeader(
                path, f, (rows, cols),
                _floats(pos.get("ImagePositionPatient") if pos else None, 3, path, "ImagePositionPatient"),
                _floats(ori.get("ImageOrientationPatient") if ori else None, 6, path, "ImageOrientationPatient"),
                _floats(meas.get("PixelSpacing") if meas else None, 2, path, "PixelSpacing"),
                _float(pvt.get("RescaleSlope") if pvt else None, 1.0, path, "RescaleSlope"),
                _float(pvt.get("RescaleIntercept") if pvt else None, 0.0, path, "RescaleIntercept"),
                _float(meas.get("SliceThickness") if meas else None, None, path, "SliceThickness")))
        return out
    common = dict(
        shape=(rows, cols),
        orientation=_floats(ds.get("ImageOrientationPatient"), 6, path, "ImageOrientationPatient"),
        pixel_spacing=_floats(ds.get("PixelSpacing"), 2, path, "PixelSpacing"),
        slope=_float(ds.get("RescaleSlope", ds.get("DoseGridScaling")), 1.0, path, "RescaleSlope"),
        intercept=_float(ds.get("RescaleIntercept"), 0.0, path, "RescaleIntercept"),
        thickness=_float(ds.get("SliceThickness"), None, path, "SliceThickness"))
    position = _floats(ds.get("ImagePositionPatient"), 3, path, "ImagePositionPatient")
    if n_frames == 1:
        return [SliceHeader(path, None, position=position, **common)]
    # legacy multi-frame: frames are parallel slices starting at ImagePositionPatient
    offsets = ds.get("GridFrameOffsetVector")
    assumed = offsets is None
    if assumed:
        step = _float(ds.get("SpacingBetweenSlices"), None, path, "SpacingBetweenSlices") or common["thickness"]
        offsets = None if step is None else [f * step for f in range(n_frames)]
    offsets = _floats(offsets, n_frames, path, "GridFrameOffsetVector")
    if offsets is not None:  # relative (first is 0) or absolute (first is the position's z): frame 0 at IPP
        offsets = [v - offsets[0] for v in offsets]
    if position is None or common["orientation"] is None or offsets is None:
        raise SeriesError(path, f"multi-frame file with {n_frames} frames but no per-frame positions "
                                "(no PerFrameFunctionalGroupsSequence, GridFrameOffsetVector or slice spacing)")
    o = np.asarray(common["orientation"])
    normal = np.cross(o[:3], o[3:])
    return [SliceHeader(path, f, position=tuple(np.asarray(position) + off * normal), position_assumed=assumed,
                        **common) for f, off in enumerate(offsets)]


def _as_list(value) -> list:
    if value is None or value == "":
        return []
    return list(value) if isinstance(value, (list, tuple, MultiValue)) else [value]


def _info(ds) -> dict:
    """Technical, non-identifying facts of a series (from its first file)."""
    ts = getattr(ds.get("file_meta", None), "TransferSyntaxUID", None)
    pvt, voi = None, ds
    if "PerFrameFunctionalGroupsSequence" in ds or "SharedFunctionalGroupsSequence" in ds:
        first = (ds.get("PerFrameFunctionalGroupsSequence") or [None])[0]
        pvt = _item(ds, "PixelValueTransformationSequence", first)
        voi = _item(ds, "FrameVOILUTSequence", first)
    presets = []
    if voi is not None and "WindowCenter" in voi and "WindowWidth" in voi:
        centers, widths, names = (_as_list(voi.get(k)) for k in
                                  ("WindowCenter", "WindowWidth", "WindowCenterWidthExplanation"))
        try:
            for i, (c, w) in enumerate(zip(centers, widths)):
                presets.append({"center": float(c), "width": float(w),
                                "name": str(names[i]) if i < len(names) else ""})
        except (TypeError, ValueError):
            presets = []  # unusable presets are not worth failing a load
    sop = ds.get("SOPClassUID")
    return {
        "modality": str(ds.get("Modality", "") or "OT"),
        "manufacturer": str(ds.get("Manufacturer", "") or ""),
        "manufacturer_model": str(ds.get("ManufacturerModelName", "") or ""),
        "sop_class": sop.name if sop is not None else "",
        "transfer_syntax": ts.name if ts is not None else "",
        "rescale_type": str((pvt or ds).get("RescaleType", "") or ds.get("DoseUnits", "") or ""),
        "samples_per_pixel": int(ds.get("SamplesPerPixel", 1) or 1),
        "photometric": str(ds.get("PhotometricInterpretation", "") or ""),
        "window_presets": presets,
    }


def read_headers(paths: list[Path], notes: list[str], dicomdirs: list[str]) -> dict[str, SeriesHeaders]:
    """Read the headers of ``paths`` and group the image slices by SeriesInstanceUID.

    Files that are not DICOM (no ``DICM`` preamble and no DICOM suffix) and DICOMDIR
    files are skipped silently (DICOMDIRs listed in ``dicomdirs``); DICOM files without
    image data get a line in ``notes``.
    Raises :class:`CorruptDataError` for a DICOM file whose header cannot be read.
    """
    series: dict[str, SeriesHeaders] = {}
    for p in paths:
        path = str(p)
        ds = None
        with warnings.catch_warnings():  # pydicom warnings may quote element values
            warnings.simplefilter("ignore")
            try:
                ds = pydicom.dcmread(path, stop_before_pixels=True)
            except InvalidDicomError:
                if p.suffix.lower() not in DICOM_SUFFIXES and p.name.upper() != "DICOMDIR":
                    continue
                try:
                    ds = pydicom.dcmread(path, stop_before_pixels=True, force=True)
                except Exception:  # noqa: BLE001 - anything pydicom raises means "unreadable"
                    ds = None
                if ds is None or ("Rows" not in ds and "SOPClassUID" not in ds):
                    raise CorruptDataError(path, "has a DICOM suffix but is not a readable DICOM file") from None
            except Exception as exc:  # noqa: BLE001
                raise CorruptDataError(path, f"is not a readable DICOM file ({type(exc).__name__})") from None
        sop = str(ds.get("SOPClassUID", "") or getattr(ds.get("file_meta", None), "MediaStorageSOPClassUID", ""))
        if sop == _DICOMDIR_CLASS or "DirectoryRecordSequence" in ds:
            dicomdirs.append(path)
            continue
        if "Rows" not in ds or "Columns" not in ds:
            kind = pydicom.uid.UID(sop).name if sop else "unknown SOP class"
            if "Image Storage" in kind:
                raise CorruptDataError(path, f"is a {kind} file without image size or pixel data (truncated?)")
            notes.append(f"skipped {path}: DICOM file without pixel data ({kind})")
            continue
        uid = str(ds.get("SeriesInstanceUID", "") or "(no SeriesInstanceUID)")
        if uid not in series:
            series[uid] = SeriesHeaders(uid, str(ds.get("SeriesDescription", "") or ""), _info(ds))
        series[uid].slices.extend(_slices_of(ds, path))
        series[uid].files.append(path)
    return series


@dataclass
class Geometry:
    """Slice order and voxel geometry of a series.

    ``order[k]`` is the index (into the series' slice list) of data slice ``k``;
    ``positions`` (n,) mm are the slices' positions along the slice normal, ascending;
    ``affine`` maps (i, j, k, 1) = (column, row, slice) to RAS+ mm; ``spacing`` is
    ``(dz, dy, dx)`` mm, the norms of the affine's k, j, i columns.
    """

    order: np.ndarray
    positions: np.ndarray
    affine: np.ndarray
    spacing: tuple[float, float, float]
    uniform: bool
    normal_lps: np.ndarray
    warnings: list[str]
    tilt_deg: float = 0.0


def _check_same(slices: list[SliceHeader], key, what: str, where, close=None) -> None:
    first = key(slices[0])
    for s in slices[1:]:
        v = key(s)
        same = v == first if close is None else close(v, first)
        if not same:
            raise SeriesError(where, f"mixed {what} in one series: {first} in {slices[0].label()} but {v} in "
                                     f"{s.label()}")


def measure(slices: list[SliceHeader], where) -> Geometry:
    """Order ``slices`` along their normal and compute affine (RAS+) and spacing.

    The normal is ``row cosine x column cosine`` (ImageOrientationPatient); slices are
    sorted by ImagePositionPatient projected on it. The k column of the affine is
    ``(position of the last slice - position of the first) / (n - 1)``, so gantry tilt
    and oblique stacks are kept. Raises :class:`SeriesError` for mixed sizes,
    orientations or pixel spacings, missing positions and duplicate positions.
    """
    notes: list[str] = []
    n = len(slices)
    _check_same(slices, lambda s: "x".join(map(str, s.shape[::-1])), "image sizes (columns x rows)", where)
    if any(s.orientation is None for s in slices) or any(s.position is None for s in slices):
        if n > 1:
            bad = next(s for s in slices if s.orientation is None or s.position is None)
            raise SeriesError(where, f"{bad.label()} has no ImagePositionPatient / ImageOrientationPatient, "
                                     f"so the {n} slices cannot be ordered")
        notes.append("no ImagePositionPatient / ImageOrientationPatient: assumed an axial slice at the origin")
        slices = [replace(slices[0], position=slices[0].position or (0.0, 0.0, 0.0),
                          orientation=slices[0].orientation or (1.0, 0.0, 0.0, 0.0, 1.0, 0.0))]
    _check_same(slices, lambda s: tuple(round(v, 6) for v in s.orientation), "orientations (ImageOrientationPatient)",
                where, lambda a, b: np.allclose(a, b, atol=_SAME_ORIENTATION))
    _check_same(slices, lambda s: s.pixel_spacing, "pixel spacings (PixelSpacing)", where,
                lambda a, b: (a is None and b is None) or (a is not None and b is not None
                                                           and np.allclose(a, b, rtol=1e-4)))
    iop = np.asarray(slices[0].orientation, float)
    row_dir, col_dir = iop[:3] / np.linalg.norm(iop[:3]), iop[3:] / np.linalg.norm(iop[3:])
    normal = np.cross(row_dir, col_dir)
    if np.linalg.norm(normal) < 0.5:
        raise SeriesError(where, f"ImageOrientationPatient {tuple(iop)} has parallel row and column directions")
    normal /= np.linalg.norm(normal)
    if slices[0].pixel_spacing is None:
        notes.append("no PixelSpacing: assumed 1 mm x 1 mm pixels")
    dy, dx = slices[0].pixel_spacing or (1.0, 1.0)
    ipp = np.array([s.position for s in slices], float)
    proj = ipp @ normal
    order = np.argsort(proj, kind="stable")
    pos, ipp = proj[order], ipp[order]
    if any(s.position_assumed for s in slices):
        notes.append("multi-frame file without per-frame positions: frames assumed evenly spaced by "
                     "SpacingBetweenSlices / SliceThickness")
    gaps = np.diff(pos)
    dup = np.flatnonzero(gaps < _DUPLICATE_MM)
    if dup.size:
        a, b = slices[order[dup[0]]], slices[order[dup[0] + 1]]
        raise SeriesError(where, f"{dup.size} slice(s) share a position with another, e.g. {a.label()} and "
                                 f"{b.label()} at {pos[dup[0]]:.3f} mm along the slice normal; a series holding "
                                 "several time points, echoes or stacks is not one volume (no slice was dropped)")
    uniform, tilt = True, 0.0
    if n == 1:
        dz = slices[0].thickness if slices[0].thickness and slices[0].thickness > 0 else 1.0
        notes.append(f"single-slice series: slice spacing taken as {dz:g} mm "
                     f"({'SliceThickness' if slices[0].thickness else 'assumed'})")
        k_col = normal * dz
    else:
        k_col = (ipp[-1] - ipp[0]) / (n - 1)
        mean = (pos[-1] - pos[0]) / (n - 1)
        tol = max(_UNIFORM_MM, _UNIFORM_REL * mean)
        if np.any(np.abs(gaps - mean) > tol):
            uniform = False
            notes.append(f"non-uniform slice spacing: gaps between {gaps.min():.4g} and {gaps.max():.4g} mm along "
                         f"the slice normal (mean {mean:.4g} mm); loaded as is: the affine uses the mean spacing, "
                         "the true positions are in meta['slice_positions']; load with resample=True for a "
                         "uniform grid")
        cosang = abs(float(k_col @ normal)) / np.linalg.norm(k_col)
        tilt = float(np.degrees(np.arccos(min(cosang, 1.0))))
        if tilt > 0.01:
            notes.append(f"slices are sheared (gantry tilt of {tilt:.2f} degrees); the affine keeps the shear")
        # positions off the line from the first to the last slice
        t = (pos - pos[0]) / (pos[-1] - pos[0])
        off = np.linalg.norm(ipp - (ipp[0] + t[:, None] * (ipp[-1] - ipp[0])), axis=1).max()
        if off > max(0.01, 0.01 * min(dx, dy)):
            notes.append(f"slice positions are not on one line (up to {off:.3g} mm off); the affine uses the "
                         "first and the last slice")
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = row_dir * dx, col_dir * dy, k_col, ipp[0]
    affine = _LPS_TO_RAS @ m
    spacing = (float(np.linalg.norm(k_col)), float(dy), float(dx))
    return Geometry(order, pos, affine, spacing, uniform, normal, notes, tilt)
