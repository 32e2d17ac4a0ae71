"""VTK legacy ``DATASET STRUCTURED_POINTS`` files (``.vtk``), parsed here without VTK.

Layout read::

    # vtk DataFile Version x.y
    <title line>
    ASCII | BINARY
    DATASET STRUCTURED_POINTS
    DIMENSIONS nx ny nz
    SPACING sx sy sz            (or ASPECT_RATIO)
    ORIGIN ox oy oz
    POINT_DATA n
    SCALARS name type [ncomp]
    LOOKUP_TABLE default
    <n * ncomp values: whitespace-separated text, or big-endian binary>

``DIMENSIONS``, ``SPACING`` and ``ORIGIN`` may come in any order. Types:
``unsigned_char``, ``char``, ``short``, ``unsigned_short``, ``int``,
``unsigned_int``, ``float``, ``double`` (and the ``vtktypeint16``-style names).
Samples run x fastest, so the values reshape to ``[z, y, x]`` directly. With
several components only the first is kept (a warning says so).

Orientation: VTK's world frame has no patient convention. volumen takes it as
**LPS+**, the frame ITK's ``VTKImageIO`` (and therefore SimpleITK) and 3D Slicer
put these files in: voxel (i, j, k) is at LPS ``origin + (i*sx, j*sy, k*sz)``,
so the RAS+ affine is ``diag(-sx, -sy, sz)`` with origin ``(-ox, -oy, oz)``.
``meta["vtk_frame"]`` records ``"LPS"``.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np

from ..core import Volume
from ..errors import CorruptDataError, DataSizeError, UnknownFormatError
from . import _header_limits as lim
from ._numpy import native

__all__ = ["read"]

_TYPES = {
    "unsigned_char": "u1", "char": "i1", "short": "i2", "unsigned_short": "u2", "int": "i4",
    "unsigned_int": "u4", "float": "f4", "double": "f8", "vtktypeint8": "i1", "vtktypeuint8": "u1",
    "vtktypeint16": "i2", "vtktypeuint16": "u2", "vtktypeint32": "i4", "vtktypeuint32": "u4",
    "vtktypeint64": "i8", "vtktypeuint64": "u8", "vtktypefloat32": "f4", "vtktypefloat64": "f8",
}
_FLIP = np.array([-1.0, -1.0, 1.0])  # LPS <-> RAS


class _Lines:
    """Iterate over the non-blank lines of a byte buffer, keeping the byte position."""

    def __init__(self, buf: bytes, path: Path):
        self.buf, self.pos, self.path = buf, 0, path

    def next(self, what: str) -> str:
        while self.pos < len(self.buf):
            end = self.buf.find(b"\n", self.pos)
            end = len(self.buf) if end < 0 else end
            line = self.buf[self.pos:end].decode("latin-1").strip()
            self.pos = end + 1
            if line:
                return line
        raise CorruptDataError(self.path, f"the VTK header ends before {what}")


def _numbers(path: Path, line: str, n: int, kind=float) -> list:
    parts = line.split()[1:]
    try:
        if len(parts) != n:
            raise ValueError(f"expected {n} numbers")
        values = [kind(p) for p in parts]
        if not all(math.isfinite(v) for v in values):
            raise ValueError("not finite")
        return values
    except ValueError as exc:
        raise CorruptDataError(path, f"bad VTK header line {line!r} ({exc})") from exc


def read(path) -> Volume:
    """Read a legacy VTK structured-points file.

    Returns
    -------
    Volume
        Data ``[z, y, x]`` (DIMENSIONS ``nx ny nz``) in the file's type, native
        byte order; spacing ``(sz, sy, sx)`` mm; affine voxel (i, j, k) -> RAS+ mm
        with the file's frame taken as LPS (module docstring).
    """
    path = Path(path)
    buf = path.read_bytes()
    if not re.match(rb"#\s*vtk DataFile Version", buf[:64], re.IGNORECASE):
        raise CorruptDataError(path, "is not a VTK legacy file (no '# vtk DataFile Version' line)")
    lines = _Lines(buf, path)
    lines.next("the version line")
    end = buf.find(b"\n", lines.pos)  # the title may be blank: skip exactly one line
    lines.pos = len(buf) if end < 0 else end + 1
    mode = lines.next("ASCII/BINARY").upper()
    if mode not in ("ASCII", "BINARY"):
        raise CorruptDataError(path, f"third line must be ASCII or BINARY, got {mode[:40]!r}")
    dataset = lines.next("DATASET").split()
    if len(dataset) < 2 or dataset[0].upper() != "DATASET":
        raise CorruptDataError(path, f"expected a DATASET line, got {' '.join(dataset)[:60]!r}")
    if dataset[1].upper() != "STRUCTURED_POINTS":
        raise UnknownFormatError(path, f"VTK dataset {dataset[1]} is not a volume; volumen reads "
                                       "DATASET STRUCTURED_POINTS only")
    dims = spacing = origin = None
    n_points = None
    while True:
        line = lines.next("POINT_DATA and SCALARS")
        key = line.split()[0].upper()
        if key == "DIMENSIONS":
            dims = _numbers(path, line, 3, int)
        elif key in ("SPACING", "ASPECT_RATIO"):
            spacing = _numbers(path, line, 3)
        elif key == "ORIGIN":
            origin = _numbers(path, line, 3)
        elif key == "POINT_DATA":
            n_points = _numbers(path, line, 1, int)[0]
        elif key == "SCALARS":
            break
        elif key in ("CELL_DATA", "FIELD", "VECTORS", "NORMALS", "COLOR_SCALARS", "TENSORS"):
            raise CorruptDataError(path, f"volumen reads POINT_DATA SCALARS only; found {key} first")
    if dims is None or min(dims) < 1:
        raise CorruptDataError(path, f"missing or bad DIMENSIONS {dims}")
    nx, ny, nz = dims
    count = nx * ny * nz
    lim.need_bytes(path, dims, 1, "DIMENSIONS")
    if n_points is None or n_points != count:
        raise CorruptDataError(path, f"POINT_DATA {n_points} does not match DIMENSIONS {nx}x{ny}x{nz} = {count}")
    parts = line.split()
    if len(parts) < 3 or parts[2].lower() not in _TYPES:
        raise CorruptDataError(path, f"bad SCALARS line {line!r}; types are {', '.join(list(_TYPES)[:8])}")
    ncomp = lim.to_int(path, "SCALARS components", parts[3], 1, 4) if len(parts) > 3 else 1
    dtype = np.dtype(_TYPES[parts[2].lower()])
    look = lines.next("LOOKUP_TABLE")
    if not look.upper().startswith("LOOKUP_TABLE"):
        raise CorruptDataError(path, f"expected LOOKUP_TABLE after SCALARS, got {look[:60]!r}")
    n_values = count * ncomp
    lim.need_bytes(path, [n_values], dtype.itemsize, "DIMENSIONS and SCALARS")
    if mode == "BINARY":
        nbytes = n_values * dtype.itemsize
        have = len(buf) - lines.pos
        if have < nbytes:
            raise DataSizeError(path, f"binary data too short: {nx}x{ny}x{nz}x{ncomp} {parts[2]} needs "
                                      f"{nbytes} bytes, the file has {have} after the header")
        values = np.frombuffer(buf, dtype=dtype.newbyteorder(">"), count=n_values, offset=lines.pos)
    else:
        text = buf[lines.pos:]
        tokens = text.split(maxsplit=n_values)[:n_values] if n_values <= len(text) else []
        if len(tokens) < n_values:
            raise DataSizeError(path, f"ASCII data too short: {nx}x{ny}x{nz}x{ncomp} needs {n_values} "
                                      f"values, the file has {len(tokens)}")
        try:
            values = np.array(tokens, dtype=np.float64 if dtype.kind == "f" else np.int64).astype(dtype)
        except (ValueError, OverflowError) as exc:
            raise CorruptDataError(path, f"ASCII data holds a bad number ({exc})") from exc
    data = values.reshape(nz, ny, nx, ncomp)[..., 0]
    warnings = [f"{ncomp} components per point: read the first only"] if ncomp > 1 else []
    step = np.array(spacing if spacing is not None else [1.0, 1.0, 1.0], dtype=float)
    if not np.all((step > 0) & np.isfinite(step)):
        raise CorruptDataError(path, f"SPACING must be positive and finite, got {step.tolist()}")
    affine = np.eye(4)
    affine[:3, :3] = np.diag(_FLIP * step)
    affine[:3, 3] = _FLIP * np.array(origin if origin is not None else [0.0, 0.0, 0.0], dtype=float)
    meta = {"warnings": warnings, "vtk_frame": "LPS", "vtk_scalars": parts[1], "vtk_encoding": mode.lower()}
    try:
        return Volume(native(data), spacing=(step[2], step[1], step[0]), affine=affine,
                      name=path.name.split(".")[0], meta=meta)
    except ValueError as exc:  # a non-finite ORIGIN, or spacings whose product overflows
        raise CorruptDataError(path, f"has unusable geometry: {exc}") from exc
