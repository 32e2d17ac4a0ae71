"""MetaImage (``.mha``, ``.mhd`` with ``.raw``/``.zraw``) through SimpleITK.

ITK's physical space is LPS+: the affine is built from ITK's origin, spacing and
direction, ``A_lps = [D * spacing | origin]``, and turned into RAS+ by negating
its x and y rows (``diag(-1, -1, 1, 1) @ A_lps``); writing does the reverse.
``GetArrayFromImage`` already gives ``[z, y, x]``.

Before handing the file to SimpleITK the text header is read here, so that a
file that is not MetaImage, a missing detached data file, or uncompressed data
shorter than ``DimSize`` says raise typed errors naming the file.

Precision: ITK writes ``Offset``, ``ElementSpacing`` and ``TransformMatrix`` with
17 significant digits, so each round-trips exactly; but the affine is rebuilt as
direction times spacing, which can differ from the original affine by an ulp.
The writer therefore also stores the JSON geometry record (see
:mod:`volumen.io._numpy`) as a ``Volumen`` header field, and the reader uses it
when it agrees with ITK's geometry within 1e-12 (relative).
"""

from __future__ import annotations

import os
import zlib
from pathlib import Path

import numpy as np

from ..core import Volume
from ..errors import CorruptDataError, DataSizeError, MissingPathError, VolumeWriteError
from ._numpy import apply_record, geometry_record, native, parse_record

__all__ = ["read", "write"]

_FLIP = np.diag([-1.0, -1.0, 1.0, 1.0])  # LPS <-> RAS, its own inverse
_MET_SIZES = {"MET_CHAR": 1, "MET_UCHAR": 1, "MET_SHORT": 2, "MET_USHORT": 2, "MET_INT": 4, "MET_UINT": 4,
              "MET_LONG": 4, "MET_ULONG": 4, "MET_LONG_LONG": 8, "MET_ULONG_LONG": 8, "MET_FLOAT": 4,
              "MET_DOUBLE": 8}
_MODALITIES = {"MET_MOD_CT": "CT", "MET_MOD_MR": "MR", "MET_MOD_NM": "NM", "MET_MOD_US": "US"}
_RECORD_KEY = "Volumen"


def _header(path: Path) -> tuple[dict[str, str], int]:
    """Header fields and the byte offset just after the ``ElementDataFile`` line."""
    fields: dict[str, str] = {}
    pos = 0
    with open(path, "rb") as f:
        for _ in range(1000):
            line = f.readline(65536)
            if not line:
                break
            pos += len(line)
            text = line.decode("latin-1").strip()
            if not text:
                continue
            key, eq, value = text.partition("=")
            if not eq or not key.strip() or not key.strip().replace("_", "").isalnum():
                break
            fields[key.strip()] = value.strip()
            if key.strip() == "ElementDataFile":
                return fields, pos
    raise CorruptDataError(path, "is not a MetaImage file (no 'Key = Value' header ending in ElementDataFile)")


def _check_data(path: Path, fields: dict[str, str], data_start: int, warnings: list[str]) -> None:
    """Raise for a missing detached file or uncompressed data shorter than the header says."""
    datafile = fields["ElementDataFile"]
    if datafile.upper().startswith("LIST") or "%" in datafile:
        return  # ITK handles the list forms; its own errors are wrapped
    local = datafile.upper() == "LOCAL"
    target = path if local else (path.parent / datafile)
    if not local and not target.exists():
        raise MissingPathError(path, f"the data file {datafile!r} named by ElementDataFile does not exist")
    try:
        dims = [int(n) for n in fields.get("DimSize", "").split()]
        nch = int(fields.get("ElementNumberOfChannels", "1"))
        size = _MET_SIZES[fields.get("ElementType", "").upper()]
        skip = int(fields.get("HeaderSize", "0"))
    except (ValueError, KeyError):
        return  # let ITK judge the header
    if not dims or skip < 0:
        return
    expected = int(np.prod(dims)) * nch * size
    if fields.get("CompressedData", "False").lower() == "true":
        _check_zlib(path, target, data_start if local else skip, expected)
        return
    available = os.path.getsize(target) - (data_start if local else skip)
    if available < expected:
        raise DataSizeError(path, f"image data too short: DimSize {dims} of {fields['ElementType']} needs "
                                  f"{expected} bytes, {target.name} has {max(available, 0)}")
    if available > expected:
        warnings.append(f"{target.name} holds {available - expected} bytes more than the header describes")


def _check_zlib(path: Path, target: Path, start: int, expected: int) -> None:
    """Inflate a compressed data block chunk by chunk (output discarded) to check it and its size.

    ITK only prints "Uncompress failed" and returns zeros for a broken stream,
    so the stream is checked here first.
    """
    inflate = zlib.decompressobj()
    produced = 0
    try:
        with open(target, "rb") as f:
            f.seek(start)
            while chunk := f.read(1 << 20):
                produced += len(inflate.decompress(chunk, 1 << 24))  # bounded output per call
                while inflate.unconsumed_tail:
                    produced += len(inflate.decompress(inflate.unconsumed_tail, 1 << 24))
                if inflate.eof:
                    break
    except zlib.error as exc:
        raise CorruptDataError(path, f"compressed data in {target.name} is broken ({exc})") from exc
    if not inflate.eof or produced != expected:
        raise DataSizeError(path, f"compressed data in {target.name} inflates to {produced} bytes"
                                  f"{'' if inflate.eof else ' and is cut short'}; the header needs {expected}")


def read(path) -> Volume:
    """Read a MetaImage file.

    Returns
    -------
    Volume
        Data ``[z, y, x]`` in its stored dtype; spacing ``(dz, dy, dx)`` mm from
        ``ElementSpacing``; affine voxel (i, j, k) -> RAS+ mm.
    """
    import SimpleITK as sitk

    path = Path(path)
    warnings: list[str] = []
    fields, start = _header(path)
    _check_data(path, fields, start, warnings)
    try:
        img = sitk.ReadImage(os.fspath(path))
        arr = sitk.GetArrayFromImage(img)
    except RuntimeError as exc:
        lines = [ln.strip() for ln in str(exc).splitlines() if ln.strip()]
        detail = next((ln for ln in lines if ln.startswith("Description")), lines[-1] if lines else "")
        raise CorruptDataError(path, f"SimpleITK could not read it ({detail})") from exc
    dim = img.GetDimension()
    if img.GetNumberOfComponentsPerPixel() > 1:
        warnings.append(f"{img.GetNumberOfComponentsPerPixel()} components per voxel: read the first only")
        arr = arr[..., 0]
    if dim > 3:
        warnings.append(f"{dim}-D image: read the first volume only")
        arr = arr.reshape((-1,) + arr.shape[-3:])[0]
    elif dim == 2:
        arr = arr[None]
    n = min(dim, 3)
    spacing = np.ones(3)
    spacing[:n] = img.GetSpacing()[:n]
    origin = np.zeros(3)
    origin[:n] = img.GetOrigin()[:n]
    direction = np.eye(3)
    direction[:n, :n] = np.array(img.GetDirection(), dtype=float).reshape(dim, dim)[:n, :n]
    lps = np.eye(4)
    lps[:3, :3] = direction * spacing
    lps[:3, 3] = origin
    affine = _FLIP @ lps
    rec = parse_record(img.GetMetaData(_RECORD_KEY)) if img.HasMetaDataKey(_RECORD_KEY) else None
    affine, spacing3, extras = apply_record(rec, affine, tuple(spacing[::-1]), rtol=1e-12,
                                            what="ITK geometry", warnings=warnings)
    modality = extras.get("modality") or _MODALITIES.get(fields.get("Modality", ""), "OT")
    meta = {"warnings": warnings, "itk_pixel_type": img.GetPixelIDTypeAsString(),
            "metaimage_data_file": fields.get("ElementDataFile", "")}
    try:
        return Volume(native(arr), spacing=spacing3, affine=affine, modality=modality,
                      units=extras.get("units", ""), name=extras.get("name") or path.name.split(".")[0],
                      meta=meta)
    except ValueError as exc:
        raise CorruptDataError(path, f"has unusable geometry: {exc}") from exc


def write(volume: Volume, path, *, compress: bool = False) -> None:
    """Write ``.mha`` (data inside) or ``.mhd`` (+ ``.raw``, or ``.zraw`` with ``compress``).

    Data ``[z, y, x]`` keeps its dtype; origin, spacing and direction are written
    in LPS+ with 17 digits, the exact float64 affine in the ``Volumen`` field.
    """
    import SimpleITK as sitk

    path = Path(path)
    lps = _FLIP @ np.asarray(volume.affine, dtype=np.float64)
    spacing_xyz = np.array(volume.spacing[::-1], dtype=np.float64)
    try:
        img = sitk.GetImageFromArray(native(volume.data), isVector=False)
        img.SetSpacing([float(s) for s in spacing_xyz])
        img.SetOrigin([float(v) for v in lps[:3, 3]])
        img.SetDirection([float(v) for v in (lps[:3, :3] / spacing_xyz).ravel()])
        img.SetMetaData(_RECORD_KEY, geometry_record(volume))
        sitk.WriteImage(img, os.fspath(path), useCompression=bool(compress))
    except RuntimeError as exc:
        raise VolumeWriteError(path, f"SimpleITK could not write it ({str(exc).strip().splitlines()[-1]})") from exc
