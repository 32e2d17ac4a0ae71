"""Headerless raw volumes (``.raw``, ``.bin``): the caller says shape, type and geometry.

The file holds ``nz * ny * nx`` samples in C order (x fastest, then y, then z),
possibly after ``offset`` bytes of header. Its size is checked exactly: a file
shorter than the data, or longer without ``allow_trailing=True``, raises
:class:`~volumen.errors.DataSizeError` stating expected and actual bytes.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..core import Volume
from ..errors import DataSizeError, VolumeReadError
from ._numpy import native, spacing_of

__all__ = ["read"]

_ORDERS = {"little": "<", "<": "<", "big": ">", ">": ">", "native": "=", "=": "="}


def read(path, *, shape=None, dtype=None, spacing=None, byte_order: str = "little", offset: int = 0,
         affine=None, allow_trailing: bool = False, modality: str = "OT", units: str = "") -> Volume:
    """Read a headerless raw volume.

    Parameters
    ----------
    path : path
        The raw file.
    shape : (3,) int
        ``(nz, ny, nx)``: slices, rows, columns; x varies fastest in the file.
    dtype : numpy dtype or str
        Sample type, e.g. ``"int16"``, ``"uint8"``, ``"float32"``.
    spacing : (3,) float, mm, optional
        ``(dz, dy, dx)``. Default: the column lengths of ``affine``, or 1 mm.
    byte_order : {"little", "big", "<", ">", "native", "="}
        Byte order of multi-byte samples. The returned data is in native order.
    offset : int
        Bytes to skip at the start of the file (a header).
    affine : (4, 4) float, optional
        Voxel (i, j, k) -> RAS+ mm. Default: axis-aligned RAS with ``spacing``.
    allow_trailing : bool
        Accept (and ignore) bytes after the data instead of raising.
    modality, units : str
        Stored on the volume as given.

    Returns
    -------
    Volume
        Data ``[z, y, x]`` of ``dtype`` (native byte order).

    Raises
    ------
    VolumeReadError
        ``shape`` or ``dtype`` missing or invalid, or a bad ``byte_order``/``offset``.
    DataSizeError
        The file is shorter (or, without ``allow_trailing``, longer) than
        ``offset + nz * ny * nx * itemsize`` bytes.
    """
    path = Path(path)
    if shape is None or dtype is None:
        missing = " and ".join(n for n, v in (("shape", shape), ("dtype", dtype)) if v is None)
        raise VolumeReadError(path, f"a raw file has no header: give {missing} (shape=(nz, ny, nx), "
                                    "dtype='int16', spacing=(dz, dy, dx) mm, byte_order='little' or 'big', "
                                    "offset=header bytes)")
    try:
        shape = tuple(int(n) for n in shape)
        dt = np.dtype(dtype)
    except (TypeError, ValueError) as exc:
        raise VolumeReadError(path, f"invalid raw options shape={shape!r}, dtype={dtype!r}: {exc}") from exc
    if len(shape) != 3 or min(shape) < 1:
        raise VolumeReadError(path, f"shape must be three positive sizes (nz, ny, nx), got {shape}")
    if dt.kind not in "biuf":
        raise VolumeReadError(path, f"dtype must be a bool, integer or float type, got {dt}")
    if byte_order not in _ORDERS:
        raise VolumeReadError(path, f"byte_order must be one of {sorted(_ORDERS)}, got {byte_order!r}")
    if int(offset) < 0:
        raise VolumeReadError(path, f"offset must be >= 0 bytes, got {offset}")
    offset = int(offset)
    if dt.itemsize > 1:
        dt = dt.newbyteorder(_ORDERS[byte_order])
    count = shape[0] * shape[1] * shape[2]
    expected = count * dt.itemsize
    actual = os.path.getsize(path) - offset
    if actual < expected or (actual > expected and not allow_trailing):
        what = "short" if actual < expected else "long (pass allow_trailing=True to ignore the rest)"
        raise DataSizeError(path, f"raw data too {what}: shape {shape} of {dt.name} needs {expected} bytes "
                                  f"after offset {offset}, the file has {max(actual, 0)}")
    data = np.fromfile(path, dtype=dt, count=count, offset=offset).reshape(shape)
    warnings = []
    if spacing is None and affine is None:
        warnings.append("raw file without spacing= or affine=: geometry unknown, 1 mm axis-aligned RAS assumed")
    if spacing is None:
        spacing = spacing_of(affine) if affine is not None else (1.0, 1.0, 1.0)
    try:
        return Volume(native(data), spacing=spacing, affine=affine, modality=modality, units=units,
                      name=path.name.split(".")[0], meta={"warnings": warnings, "raw_dtype": dt.str})
    except ValueError as exc:
        raise VolumeReadError(path, f"invalid raw geometry: {exc}") from exc
