"""MetaImage (``.mha``, ``.mhd`` with ``.raw``/``.zraw`` or a list of files), parsed here.

The header is ``Key = Value`` text ending with ``ElementDataFile``; every value is
validated (:mod:`volumen.io._header_limits`) before it is used, so no header can crash,
hang or exhaust memory: native readers are never handed the file. Data: binary
(either byte order) or ASCII, zlib-compressed or not, ``LOCAL`` (after the header),
one detached file, ``LIST [nD]`` (file names follow the header, one per line) or a
pattern ``name%03d.raw min max step [n]``. Detached files must lie in the header's
folder unless ``allow_outside=True``.

ITK's physical space is LPS+: ``TransformMatrix`` lists the direction of each axis in
turn (ITK's ``MetaImageIO``), so the direction matrix ``D`` has those as columns and
``A_lps = [D * spacing | Offset]``; RAS+ is ``diag(-1, -1, 1, 1) @ A_lps``. With more
than three axes the first volume is read, with several channels the first channel
(each with a warning); a 2-D image is one slice.

Precision: ITK writes ``Offset``, ``ElementSpacing`` and ``TransformMatrix`` with
17 significant digits; the affine rebuilt as direction times spacing can differ from
the original by an ulp, so the writer (SimpleITK) also stores the JSON geometry
record (see :mod:`volumen.io._numpy`) as a ``Volumen`` field, used when it agrees
with the header's geometry within 1e-12 (relative).
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from ..core import Volume
from ..errors import CorruptDataError, DataSizeError, VolumeWriteError
from . import _header_limits as lim
from ._numpy import apply_record, geometry_record, native, parse_record

__all__ = ["read", "write"]

_FLIP = np.diag([-1.0, -1.0, 1.0, 1.0])  # LPS <-> RAS, its own inverse
_TYPES = {"MET_CHAR": "i1", "MET_UCHAR": "u1", "MET_SHORT": "i2", "MET_USHORT": "u2", "MET_INT": "i4",
          "MET_UINT": "u4", "MET_LONG": "i4", "MET_ULONG": "u4", "MET_LONG_LONG": "i8", "MET_ULONG_LONG": "u8",
          "MET_FLOAT": "f4", "MET_DOUBLE": "f8"}
_MODALITIES = {"MET_MOD_CT": "CT", "MET_MOD_MR": "MR", "MET_MOD_NM": "NM", "MET_MOD_US": "US"}
_RECORD_KEY = "Volumen"
_MAX_DIMS = 8
_MAX_HEADER_LINES = 1000


def _header(path: Path) -> tuple[dict[str, str], int, list[str]]:
    """Header fields, the byte offset just after ``ElementDataFile``, and the names of a LIST."""
    fields: dict[str, str] = {}
    pos = 0
    with open(path, "rb") as f:
        for _ in range(_MAX_HEADER_LINES):
            line = f.readline(65536)
            if not line:
                break
            pos += len(line)
            text = line.decode("latin-1").strip()
            if not text:
                continue
            key, eq, value = text.partition("=")
            key = key.strip()
            if not eq or not key or not key.replace("_", "").isalnum():
                break
            fields[key] = value.strip()
            if key == "ElementDataFile":
                names = []
                if value.split()[:1] == ["LIST"]:
                    names = [ln.decode("latin-1").strip() for ln in f.read(lim.MAX_FILES * 256).splitlines()]
                return fields, pos, [n for n in names if n]
    raise CorruptDataError(path, "is not a MetaImage file (no 'Key = Value' header ending in ElementDataFile)")


def _flag(fields: dict[str, str], *keys: str) -> bool:
    return any(fields.get(k, "").strip().lower() == "true" for k in keys)


def _dtype(path: Path, fields: dict[str, str]) -> tuple[np.dtype, int]:
    etype = fields.get("ElementType", "").strip().upper()
    base = etype[:-6] if etype.endswith("_ARRAY") else etype
    if base not in _TYPES:
        raise CorruptDataError(path, f"ElementType {etype[:40]!r} is not one volumen reads ({', '.join(_TYPES)})")
    channels = lim.to_int(path, "ElementNumberOfChannels", fields.get("ElementNumberOfChannels", "1"), 1, 1024)
    msb = _flag(fields, "BinaryDataByteOrderMSB", "ElementByteOrderMSB")
    return np.dtype(_TYPES[base]).newbyteorder(">" if msb else "<"), channels


def _sources(path: Path, fields: dict[str, str], start: int, names: list[str], dims: list[int],
             allow_outside: bool) -> list[tuple[Path, int]]:
    """(file, first byte) of each data file, in order."""
    value = fields["ElementDataFile"]
    spec = value.split()
    if value.upper() == "LOCAL":
        return [(path, start)]
    skip = lim.to_int(path, "HeaderSize", fields.get("HeaderSize", "0"), -1)
    if spec[:1] == ["LIST"] or (len(spec) >= 4 and "%" in spec[0]):
        listed = spec[0] == "LIST"
        sub_text = (spec[1] if len(spec) > 1 else "") if listed else (spec[4] if len(spec) > 4 else "")
        sub = lim.to_int(path, "ElementDataFile subdimension", sub_text.upper().rstrip("D") or len(dims) - 1,
                         1, len(dims))
        count = math.prod(dims[sub:])
        if listed:
            if len(names) < count:
                raise DataSizeError(path, f"ElementDataFile LIST names {len(names)} files, the sizes need {count}")
            names = names[:count]
        else:
            lo, hi, step = (lim.to_int(path, "ElementDataFile", t, -(1 << 62)) for t in spec[1:4])
            names = lim.expand_pattern(path, spec[0], lo, hi, step, count)
        return [(lim.data_file(path, n, allow_outside), skip) for n in names]
    return [(lim.data_file(path, value, allow_outside), skip)]


def _decode(path: Path, target: Path, start: int, nbytes: int, dtype: np.dtype, fields: dict[str, str],
            warnings: list[str]) -> np.ndarray:
    """``nbytes`` worth of samples from ``target`` at ``start`` (-1: the last bytes of the file)."""
    size = os.path.getsize(target)
    if _flag(fields, "CompressedData"):
        with open(target, "rb") as f:
            f.seek(max(start, 0))
            blob = lim.inflate(path, f.read(), nbytes, "zlib", target.name)
        return np.frombuffer(blob, dtype=dtype)
    if fields.get("BinaryData", "True").strip().lower() == "false":
        count = nbytes // dtype.itemsize
        with open(target, "rb") as f:
            f.seek(max(start, 0))
            text = f.read()
        tokens = text.split(maxsplit=count)[:count] if count <= len(text) else []
        if len(tokens) < count:
            raise DataSizeError(path, f"ASCII data in {target.name} holds fewer than the {count} values needed")
        try:
            return np.array(tokens, dtype=np.float64 if dtype.kind == "f" else np.int64).astype(dtype)
        except (ValueError, OverflowError) as exc:
            raise CorruptDataError(path, f"ASCII data in {target.name} holds a bad number ({exc})") from exc
    at_end = start < 0
    start = size - nbytes if at_end else start
    have = lim.check_available(path, target, start, nbytes)
    if have > nbytes and not at_end:
        warnings.append(f"{target.name} holds {have - nbytes} bytes more than the header describes")
    return np.fromfile(target, dtype=dtype, count=nbytes // dtype.itemsize, offset=start)


def _geometry(path: Path, fields: dict[str, str], ndims: int) -> tuple[np.ndarray, tuple[float, float, float]]:
    """The RAS+ affine of the first three axes and their spacing ``(dz, dy, dx)``."""
    def pick(*keys):
        return next((fields[k] for k in keys if k in fields), None)

    text = pick("ElementSpacing", "ElementSize")
    spacing = np.array(lim.to_floats(path, "ElementSpacing", text, ndims) if text is not None else [1.0] * ndims)
    text = pick("Offset", "Position", "Origin")
    origin = np.array(lim.to_floats(path, "Offset", text, ndims) if text is not None else [0.0] * ndims)
    text = pick("TransformMatrix", "Rotation", "Orientation")
    matrix = (np.array(lim.to_floats(path, "TransformMatrix", text, ndims * ndims)).reshape(ndims, ndims).T
              if text is not None else np.eye(ndims))
    n = min(ndims, 3)
    if np.any(spacing[:n] <= 0):
        raise CorruptDataError(path, f"ElementSpacing must be positive, got {spacing.tolist()}")
    lps = np.eye(4)
    lps[:n, :n] = matrix[:n, :n] * spacing[:n]
    lps[:n, 3] = origin[:n]
    step = np.ones(3)
    step[:n] = spacing[:n]
    return _FLIP @ lps, (float(step[2]), float(step[1]), float(step[0]))


def read(path, *, allow_outside: bool = False) -> Volume:
    """Read a MetaImage file.

    Parameters
    ----------
    path : path
        A ``.mha`` or ``.mhd`` header.
    allow_outside : bool
        Read data files the header names outside its own folder (refused by default).

    Returns
    -------
    Volume
        Data ``[z, y, x]`` in its stored type (native byte order); spacing ``(dz, dy, dx)``
        mm from ``ElementSpacing``; affine voxel (i, j, k) -> RAS+ mm.
    """
    path = Path(path)
    warnings: list[str] = []
    fields, start, names = _header(path)
    if fields.get("ObjectType", "Image").strip().lower() != "image":
        raise CorruptDataError(path, f"ObjectType {fields['ObjectType'][:40]!r} is not an image")
    ndims = lim.to_int(path, "NDims", fields.get("NDims", ""), 1, _MAX_DIMS)
    dims = [lim.to_int(path, "DimSize", t, 1) for t in fields.get("DimSize", "").split()]
    if len(dims) != ndims:
        raise CorruptDataError(path, f"DimSize {fields.get('DimSize', '')[:60]!r} does not give NDims = {ndims} sizes")
    dtype, channels = _dtype(path, fields)
    total = lim.need_bytes(path, dims + [channels], dtype.itemsize, "DimSize")
    affine, spacing3 = _geometry(path, fields, ndims)
    sources = _sources(path, fields, start, names, dims, allow_outside)
    per = total // len(sources)
    flat = np.concatenate([_decode(path, f, s, per, dtype, fields, warnings) for f, s in sources])
    arr = flat.reshape(dims[::-1] + [channels])
    if channels > 1:
        warnings.append(f"{channels} components per voxel: read the first only")
    arr = arr[..., 0]
    if ndims > 3:
        warnings.append(f"{ndims}-D image: read the first volume only")
        arr = arr.reshape((-1,) + arr.shape[-3:])[0]
    arr = arr.reshape((1,) * (3 - arr.ndim) + arr.shape)
    rec = parse_record(fields[_RECORD_KEY]) if _RECORD_KEY in fields else None
    affine, spacing3, extras = apply_record(rec, affine, spacing3, rtol=1e-12, what="MetaImage geometry",
                                            warnings=warnings)
    modality = extras.get("modality") or _MODALITIES.get(fields.get("Modality", ""), "OT")
    meta = {"warnings": warnings, "metaimage_element_type": fields.get("ElementType", ""),
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
