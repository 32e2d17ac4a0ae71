"""NIfTI-1/2 (``.nii``, ``.nii.gz``, ``.hdr``/``.img`` pairs) through nibabel.

Reading
    The affine is the sform when ``sform_code > 0``, else the qform when
    ``qform_code > 0``, else nibabel's fall-back (pixdim on the axes);
    ``meta["nifti_xform"]`` says which (``"sform"``, ``"qform"``, ``"fallback"``,
    or ``"analyze"`` for plain Analyze 7.5 headers). nibabel's affines are RAS+
    already; spatial units of metres or microns are converted to mm. NIfTI arrays
    are ``[x, y, z]``: they are transposed to ``[z, y, x]`` (C-contiguous).

    ``scl_slope``/``scl_inter`` are applied. Without scaling the stored dtype is
    kept; with integer slope and intercept on integer data the result stays
    integer (int16 or int32, the smallest that holds the range, e.g. CT stored as
    uint16 with intercept -1024 comes back as int16 HU); otherwise it is float32
    for 8/16-bit or float32 storage, float64 for the rest.

    4-D (and higher) files give their first volume ``[..., 0]`` with a line in
    ``meta["warnings"]``; trailing axes of size 1 are dropped silently; a 2-D
    image becomes one slice.

Writing
    Data keeps its dtype; sform and qform are both set (code 1, scanner) and
    ``xyzt_units`` is mm. NIfTI stores the sform as float32, so the float64
    affine, spacing, modality, units and name are also written as a JSON geometry
    record (see :mod:`volumen.io._numpy`) in a header extension of code 6
    (comment). On reading, the record is used only when it agrees with the sform
    within float32 precision; otherwise the sform wins with a warning.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..core import Volume
from ..errors import CorruptDataError, DataSizeError, VolumeWriteError
from ._numpy import apply_record, geometry_record, native, parse_record, spacing_of

__all__ = ["read", "write"]

_COMMENT = 6  # NIFTI_ECODE_COMMENT
_UNIT_TO_MM = {"meter": 1000.0, "mm": 1.0, "micron": 1e-3, "unknown": 1.0}
_F32 = float(np.finfo(np.float32).eps)


def _load(path: Path):
    import nibabel as nib

    try:
        return nib.load(os.fspath(path), mmap=False)  # no map: saving over the file must not change a volume
    except Exception as exc:  # nibabel raises many types for broken headers
        raise CorruptDataError(path, f"is not a readable NIfTI/Analyze file ({type(exc).__name__}: {exc})") from exc


def _check_size(path: Path, img) -> None:
    """Raise DataSizeError when uncompressed image data is shorter than the header says."""
    fm = img.file_map.get("image")
    fname = getattr(fm, "filename", None)
    if fname is None or str(fname).lower().endswith((".gz", ".bz2", ".zst")) or not os.path.exists(fname):
        return
    proxy = img.dataobj
    if not all(hasattr(proxy, a) for a in ("offset", "shape", "dtype")):
        return
    expected = int(proxy.offset) + int(np.prod(proxy.shape)) * np.dtype(proxy.dtype).itemsize
    actual = os.path.getsize(fname)
    if actual < expected:
        raise DataSizeError(path, f"image data too short: the header needs {expected} bytes in "
                                  f"{Path(fname).name}, the file has {actual}")


def _xform(img) -> tuple[np.ndarray, str]:
    hdr = img.header
    if not hasattr(hdr, "get_sform"):
        return np.array(img.affine, dtype=float), "analyze"
    sform, scode = hdr.get_sform(coded=True)
    qform, qcode = hdr.get_qform(coded=True)
    if scode and int(scode) > 0:
        return np.array(sform, dtype=float), "sform"
    if qcode and int(qcode) > 0:
        return np.array(qform, dtype=float), "qform"
    return np.array(hdr.get_base_affine(), dtype=float), "fallback"


def _values(img, warnings: list[str]) -> np.ndarray:
    """Scaled data ``[x, y, z]`` of the first 3-D volume."""
    shape = tuple(int(n) for n in img.shape)
    proxy = img.dataobj
    if len(shape) > 3:
        if any(n > 1 for n in shape[3:]):
            warnings.append(f"{len(shape)}-D image {shape}: read the first volume [..., 0] only")
        slicer = (slice(None),) * 3 + (0,) * (len(shape) - 3)
        arr = np.asanyarray(proxy[slicer])
    else:
        arr = np.asanyarray(proxy)
    if arr.ndim == 2:
        arr = arr[:, :, None]
    elif arr.ndim == 1:
        arr = arr[:, None, None]
    raw = np.dtype(img.header.get_data_dtype())
    slope = float(getattr(proxy, "slope", 1.0))
    inter = float(getattr(proxy, "inter", 0.0))
    if arr.dtype == np.float64 and raw != np.float64 and (slope != 1.0 or inter != 0.0):
        if raw.kind in "iu" and slope.is_integer() and inter.is_integer() and arr.size:
            lo, hi = float(arr.min()), float(arr.max())
            for t in (np.int16, np.int32):
                if np.iinfo(t).min <= lo and hi <= np.iinfo(t).max:
                    return arr.astype(t)
        if raw == np.float32 or (raw.kind in "iu" and raw.itemsize <= 2):
            return arr.astype(np.float32)
    return arr


def _geometry(img, warnings: list[str]):
    """RAS+ affine, the transform's name, spacing and the geometry record's extras."""
    affine, xform = _xform(img)
    hdr = img.header
    if hasattr(hdr, "get_xyzt_units"):
        unit = hdr.get_xyzt_units()[0]
        if _UNIT_TO_MM.get(unit, 1.0) != 1.0:
            affine[:3, :] *= _UNIT_TO_MM[unit]
            warnings.append(f"spatial units were {unit}; converted to mm")
    if np.linalg.det(affine[:3, :3]) == 0:
        warnings.append(f"the {xform} is singular; pixdim on the axes used instead")
        affine = np.array(hdr.get_base_affine(), dtype=float)
    rec = None
    for ext in getattr(hdr, "extensions", []):
        if int(ext.get_code()) == _COMMENT:
            rec = parse_record(ext.get_content()) or rec
    if rec is not None and xform != "sform":
        warnings.append(f"the volumen geometry record was ignored: the file now uses its {xform}")
        rec = None
    affine, spacing, extras = apply_record(rec, affine, spacing_of(affine), rtol=_F32, what="sform",
                                           warnings=warnings)
    return affine, xform, spacing, extras


def read(path) -> Volume:
    """Read a NIfTI file (or an Analyze/NIfTI ``.hdr``/``.img`` pair).

    Returns
    -------
    Volume
        Data ``[z, y, x]`` with scaling applied; affine voxel (i, j, k) -> RAS+ mm.
        ``meta["nifti_xform"]`` names the transform used.
    """
    path = Path(path)
    img = _load(path)
    warnings: list[str] = []
    _check_size(path, img)
    try:
        xyz = _values(img, warnings)
    except DataSizeError:
        raise
    except Exception as exc:
        raise CorruptDataError(path, f"image data could not be read ({type(exc).__name__}: {exc})") from exc
    try:
        affine, xform, spacing, extras = _geometry(img, warnings)
    except (ValueError, KeyError, IndexError, TypeError, OverflowError, np.linalg.LinAlgError) as exc:
        raise CorruptDataError(path, f"has an unusable header transform ({type(exc).__name__}: {exc})") from exc
    hdr = img.header
    data = native(np.ascontiguousarray(xyz.transpose(2, 1, 0)))
    meta = {"warnings": warnings, "nifti_xform": xform, "nifti_dtype": str(hdr.get_data_dtype())}
    try:
        return Volume(data, spacing=spacing, affine=affine, modality=extras.get("modality") or "OT",
                      units=extras.get("units", ""), name=extras.get("name") or path.name.split(".")[0],
                      meta=meta)
    except ValueError as exc:
        raise CorruptDataError(path, f"has unusable geometry: {exc}") from exc


def write(volume: Volume, path) -> None:
    """Write ``volume`` as NIfTI-1 (``.nii``, ``.nii.gz``, or a ``.hdr``/``.img`` pair).

    Data is stored ``[x, y, z]`` in its own dtype without scaling; sform and qform
    (code 1) hold the affine as float32, the header extension holds it exactly.
    """
    import nibabel as nib

    path = Path(path)
    affine = np.asarray(volume.affine, dtype=np.float64)
    xyz = np.asarray(volume.data).transpose(2, 1, 0)  # a view; nibabel writes it in Fortran order
    try:
        img = nib.Nifti1Image(xyz, affine, dtype=xyz.dtype)
        img.set_sform(affine, code=1)
        img.set_qform(affine, code=1)
        hdr = img.header
        hdr.set_xyzt_units("mm", "sec")
        hdr.set_slope_inter(1.0, 0.0)
        hdr.extensions.append(nib.nifti1.Nifti1Extension(_COMMENT, geometry_record(volume).encode("utf-8")))
        nib.save(img, os.fspath(path))
    except OSError:
        raise
    except Exception as exc:
        raise VolumeWriteError(path, f"nibabel could not write it ({type(exc).__name__}: {exc})") from exc
