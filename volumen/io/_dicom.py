"""DICOM reader: a folder, a file or a list of files holding one image series -> :class:`Volume`.

Headers of every file are read first (:mod:`._dicom_series` groups them by
SeriesInstanceUID; a file that cannot be read is a note, not the end of the
folder), :mod:`._dicom_geometry` orders the slices along their normal and builds
the geometry; pixels are then decoded for the chosen series only
(:mod:`._dicom_pixels`: colour as RGB, Modality LUT applied), rescaled to physical
units (RescaleSlope / RescaleIntercept: CT in HU) and stacked ``[slice, row, column]``
= ``[z, y, x]`` (``[z, y, x, 3]`` for colour). DICOM is LPS+; the affine is turned
into RAS+ once, in :mod:`._dicom_geometry`.

Patient identity (names, IDs, dates of birth, addresses, institutions, accession
numbers, study dates) is never copied into the volume, its warnings or any error.
"""

from __future__ import annotations

import os
from collections import defaultdict
from pathlib import Path

import numpy as np

from ..core import Volume
from ..errors import CorruptDataError, MissingPathError, MultipleSeriesError, SeriesError, UnknownFormatError
from ._dicom_geometry import Geometry, measure
from ._dicom_pixels import decode
from ._dicom_series import SeriesHeaders, read_headers

__all__ = ["read", "scan"]


def _files(path) -> tuple[list[Path], Path]:
    """The candidate files and the path to name in messages (the folder, file, or the list's common folder)."""
    if isinstance(path, (list, tuple)):
        if not path:
            raise MissingPathError(None, "an empty list of DICOM files was given")
        files: list[Path] = []
        for p in map(Path, path):
            if not p.exists():
                raise MissingPathError(p, "no such file or folder")
            files.extend(sorted(q for q in p.rglob("*") if q.is_file()) if p.is_dir() else [p])
        where = Path(os.path.commonpath([os.path.abspath(p) for p in path]))
        return files, where
    p = Path(path)
    if not p.exists():
        raise MissingPathError(p, "no such file or folder")
    if p.is_dir():
        return sorted(q for q in p.rglob("*") if q.is_file()), p
    return [p], p


def _choose(series: dict[str, SeriesHeaders], uid: str | None, where) -> SeriesHeaders:
    listing = [(s.uid, s.description, len(s.slices)) for s in series.values()]
    if uid is not None:
        if uid not in series:
            lines = "; ".join(f"{u} ({d or 'no description'}, {n} slices)" for u, d, n in listing)
            raise SeriesError(where, f"holds no series with SeriesInstanceUID {uid!r}; it holds: {lines}")
        return series[uid]
    if len(series) > 1:
        raise MultipleSeriesError(where, listing)
    return next(iter(series.values()))


def _samples(series: SeriesHeaders) -> int:
    """Values per pixel after decoding: 3 for colour (RGB, YBR_*, PALETTE COLOR), else 1."""
    info = series.info
    return 3 if info["samples_per_pixel"] == 3 or info["photometric"] == "PALETTE COLOR" else 1


def _stack(series: SeriesHeaders, geo: Geometry) -> np.ndarray:
    """Values ``(n, rows, cols)`` (or ``(n, rows, cols, 3)``) in the sorted slice order (each file read once)."""
    slices = series.slices
    dest: dict[str, list[tuple[int, int | None]]] = defaultdict(list)
    for k, idx in enumerate(geo.order):
        dest[slices[idx].path].append((k, slices[idx].frame))
    n_frames = defaultdict(int)
    for s in slices:
        n_frames[s.path] += 1
    out = None
    for path, targets in dest.items():
        multi = targets[0][1] is not None
        arr = decode(path, n_frames[path] if multi else None, slices[0].shape, _samples(series))
        if out is None:
            out = np.empty((len(slices), *arr.shape[1:]), arr.dtype)
        elif arr.dtype != out.dtype:
            out = out.astype(np.result_type(out.dtype, arr.dtype))
        for k, frame in targets:
            out[k] = arr[0 if frame is None else frame]
    return out


def _rescale(raw: np.ndarray, slopes: np.ndarray, intercepts: np.ndarray) -> tuple[np.ndarray, dict]:
    """Physical values ``raw * slope + intercept`` per slice; integers kept where that is exact."""
    same = bool(np.all(slopes == slopes[0]) and np.all(intercepts == intercepts[0]))
    if same:
        s, b = float(slopes[0]), float(intercepts[0])
        info = {"slope": s, "intercept": b}
        if s == 1.0 and b == 0.0:
            return raw, info
        if raw.dtype.kind in "iu" and s.is_integer() and b.is_integer():
            lo, hi = sorted((float(raw.min()) * s + b, float(raw.max()) * s + b))
            for dt in (raw.dtype, np.dtype(np.int16), np.dtype(np.int32), np.dtype(np.int64)):
                if np.iinfo(dt).min <= lo and hi <= np.iinfo(dt).max:
                    break
            out = np.empty(raw.shape, dt)
            for k in range(raw.shape[0]):  # per slice: int64 temporaries stay small
                out[k] = raw[k].astype(np.int64) * int(s) + int(b)
            return out, info
    else:
        info = {"per_slice": True, "slope_range": [float(slopes.min()), float(slopes.max())],
                "intercept_range": [float(intercepts.min()), float(intercepts.max())]}
    out = np.empty(raw.shape, np.float32)
    for k in range(raw.shape[0]):
        out[k] = raw[k].astype(np.float64) * slopes[k] + intercepts[k]
    return out, info


def _resample_uniform(data: np.ndarray, geo: Geometry) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Linear interpolation along the slice normal onto the smallest gap.

    Returns ``(data (m, rows, cols) float32, positions (m,) mm, k column (3,) RAS mm)``.
    """
    pos = geo.positions
    step = float(np.diff(pos).min())
    m = int(np.floor((pos[-1] - pos[0]) / step + 1e-6)) + 1
    target = pos[0] + step * np.arange(m)
    lo = np.clip(np.searchsorted(pos, target, side="right") - 1, 0, len(pos) - 2)
    w = np.clip((target - pos[lo]) / (pos[lo + 1] - pos[lo]), 0.0, 1.0)
    out = np.empty((m, *data.shape[1:]), np.float32)
    for k in range(m):  # one slice at a time, vectorised within the slice
        out[k] = (1.0 - w[k]) * data[lo[k]] + w[k] * data[lo[k] + 1]
    first_to_last = geo.affine[:3, 2] * (len(pos) - 1)  # RAS vector from the first slice to the last
    return out, target, first_to_last * step / (pos[-1] - pos[0])


def read(path, *, series: str | None = None, resample: bool = False) -> Volume:
    """Read one DICOM image series.

    Parameters
    ----------
    path : path or list of paths
        A folder (searched recursively; non-DICOM files and DICOMDIR are skipped),
        one DICOM file, or a list of files, in any order.
    series : str, optional
        SeriesInstanceUID to read when the input holds several series.
    resample : bool
        If slice gaps are not uniform, interpolate (linearly, along the slice
        normal, from the true positions) onto a uniform grid at the smallest gap.

    Returns
    -------
    Volume
        ``data`` ``[z, y, x]`` = ``[slice, row, column]`` in physical units (RescaleSlope /
        RescaleIntercept or the Modality LUT Sequence applied; CT in HU): the stored integer
        dtype when the rescale is the identity, an integer dtype wide enough when slope and
        intercept are whole numbers shared by all slices, float32 otherwise (float64 for
        DoubleFloatPixelData). Colour (RGB, YBR_*, PALETTE COLOR) is ``[z, y, x, 3]`` RGB.
        ``spacing`` ``(dz, dy, dx)`` mm, with dz from the slice positions; ``affine``
        (column, row, slice) -> RAS+ mm. ``meta`` holds technical facts only:
        ``series_uid``, ``series_description``, ``series_number``, ``slice_positions`` (mm
        along the slice normal), ``rescale``, ``window_presets``, ``transfer_syntax(_uid)``,
        ``sop_class(_uid)``, ``photometric``, ``display_inverted`` (MONOCHROME1),
        ``modality_lut``, ``voi_lut``, ``n_files``, ``warnings`` (every assumption made and
        every file skipped)...

    Raises
    ------
    MissingPathError, UnknownFormatError
        Missing path; no DICOM files.
    CorruptDataError
        A file of the chosen series that cannot be parsed or decoded (named); every file
        unreadable.
    SeriesError, MultipleSeriesError
        No images, several series and none chosen, inconsistent or duplicate slices.
    MissingDependencyError
        Compressed pixel data without an installed decoder (names what to install).
    """
    found, notes, where = scan(path)
    chosen = _choose(found, series, where)
    if chosen.bad:  # a file of this very series is broken: a slice would be missing
        path, problem = chosen.bad[0]
        raise CorruptDataError(path, f"{problem} (a file of series {chosen.uid}, which cannot load without it)")
    geo = measure(chosen.slices, where)
    info = chosen.info
    slices = [chosen.slices[i] for i in geo.order]
    data, rescale = _rescale(_stack(chosen, geo), np.array([s.slope for s in slices]),
                             np.array([s.intercept for s in slices]))
    meta = {
        "series_uid": chosen.uid, "series_description": chosen.description, "series_number": info["series_number"],
        "manufacturer": info["manufacturer"], "manufacturer_model": info["manufacturer_model"],
        "sop_class": info["sop_class"], "sop_class_uid": info["sop_class_uid"],
        "transfer_syntax": info["transfer_syntax"], "transfer_syntax_uid": info["transfer_syntax_uid"],
        "photometric": info["photometric"], "n_files": len(chosen.files), "multiframe": slices[0].frame is not None,
        "rescale": rescale, "window_presets": info["window_presets"],
        "slice_positions": [float(p) for p in geo.positions],
        "slice_normal": [float(v) for v in geo.normal_lps * (-1.0, -1.0, 1.0)],  # RAS+
        "warnings": notes + geo.warnings,
    }
    _display_facts(meta, info)
    if geo.tilt_deg > 0.01:
        meta["gantry_tilt_deg"] = geo.tilt_deg
    affine, spacing = geo.affine, geo.spacing
    if resample and not geo.uniform:
        data, new_pos, k_col = _resample_uniform(data, geo)
        affine = affine.copy()
        affine[:3, 2] = k_col
        spacing = (float(np.linalg.norm(k_col)), spacing[1], spacing[2])
        meta["source_slice_positions"] = meta["slice_positions"]
        meta["slice_positions"] = [float(p) for p in new_pos]
        meta["resampled"] = (f"non-uniform slices ({len(geo.positions)}) linearly interpolated along the slice "
                             f"normal onto {len(new_pos)} slices {new_pos[1] - new_pos[0]:.4g} mm apart")
        meta["warnings"].append(meta["resampled"])
    modality = info["modality"]
    rtype = info["rescale_type"]
    units = "" if data.ndim == 4 else (rtype if rtype and rtype.upper() != "US" else ("HU" if modality == "CT" else ""))
    return Volume(data, spacing=spacing, affine=affine, modality=modality, units=units,
                  name=chosen.description or "DICOM series", meta=meta)


def _display_facts(meta: dict, info: dict) -> None:
    """How the values should be shown: MONOCHROME1 inverted, LUTs applied or available."""
    if info["photometric"] == "MONOCHROME1":
        meta["display_inverted"] = True  # stored values kept; slice views show low values white
        meta["warnings"].append("MONOCHROME1: values kept as stored (low = white on film); slice views show "
                                "them inverted")
    if info["modality_lut"]:
        meta["modality_lut"] = f"applied ({info['modality_lut']})"
    if info["voi_lut"]:
        meta["voi_lut"] = f"not applied: available for display ({info['voi_lut']})"


def scan(path) -> tuple[dict[str, SeriesHeaders], list[str], Path]:
    """Read the headers under ``path``: ``(series by SeriesInstanceUID, notes, path for messages)``.

    Unreadable files are notes (path and cause) as long as some series is found (and
    listed in ``SeriesHeaders.bad`` of their series when their SeriesInstanceUID could be
    read); when none is found, the error says why (the unreadable file itself when there is one).
    """
    files, where = _files(path)
    if not files:
        raise UnknownFormatError(where, "is an empty folder: no DICOM files to read")
    notes: list[str] = []
    dicomdirs: list[str] = []
    bad: list[tuple[str, str, str]] = []
    found = read_headers(files, notes, dicomdirs, bad)
    if not found:
        if bad:
            first, problem, _ = bad[0]
            if len(files) == 1:
                raise CorruptDataError(first, problem)
            raise CorruptDataError(where, f"holds no readable DICOM images: {len(bad)} unreadable DICOM file(s), "
                                          f"e.g. {first}: {problem}")
        if notes or dicomdirs:
            kinds = sorted({n[n.rindex("(") + 1:-1] for n in notes if n.endswith(")")})
            what = [f"{len(notes)} DICOM file(s) without pixel data ({', '.join(kinds)})"] if notes else []
            what += [f"{len(dicomdirs)} DICOMDIR index file(s) whose images are missing"] if dicomdirs else []
            raise SeriesError(where, f"holds no DICOM images, only {' and '.join(what)}")
        if len(files) == 1 and files[0] == where:
            raise UnknownFormatError(where, "is not a DICOM file (no 'DICM' marker and no DICOM suffix)")
        raise UnknownFormatError(where, f"holds no DICOM files ({len(files)} file(s) looked at)")
    for path, problem, uid in bad:
        if uid in found:
            found[uid].bad.append((path, problem))
        notes.append(f"skipped unreadable file {path}: {problem}")
    return found, notes, where
