"""``.npy`` and ``.npz`` containers read without trusting their headers.

``numpy.load`` hands the ``.npy`` header to Python's tokenizer and allocates whatever
shape it states, so a damaged header raises TokenError, RecursionError or MemoryError.
Here the header dict is parsed with :func:`ast.literal_eval` inside a bounded length,
every entry is validated (keys, a plain ``descr`` without objects, a shape of
non-negative integers, a boolean ``fortran_order``), and the data it states is
compared with the bytes that are really there before anything is allocated. ``.npz``
members are checked against their declared sizes before they are inflated.
"""

from __future__ import annotations

import ast
import math
import zipfile
import zlib

import numpy as np

from ..errors import CorruptDataError, DataSizeError
from . import _header_limits as lim

__all__ = ["read_npy", "read_npz"]

_MAGIC = b"\x93NUMPY"
_MAX_HEADER = 1 << 16
_KINDS = "biufUS"  # numbers, and the strings volumen stores as 0-d arrays
_MAX_DEFLATE_RATIO = 1100  # deflate cannot inflate more than ~1032:1


def _header(path, head: bytes, where: str) -> tuple[np.dtype, tuple[int, ...], bool, int]:
    """dtype, shape, fortran_order and the data offset from the first bytes of an ``.npy``."""
    if not head.startswith(_MAGIC) or len(head) < 10:
        raise CorruptDataError(path, f"{where} is not a NumPy .npy array (no \\x93NUMPY magic)")
    major = head[6]
    if major not in (1, 2, 3):
        raise CorruptDataError(path, f"{where} has .npy format version {major}; versions 1 to 3 exist")
    size_len = 2 if major == 1 else 4
    hlen = int.from_bytes(head[8:8 + size_len], "little")
    start = 8 + size_len
    if hlen > _MAX_HEADER or len(head) < start + hlen:
        raise CorruptDataError(path, f"{where} states a {hlen}-byte .npy header, the file has "
                                     f"{max(len(head) - start, 0)} (limit {_MAX_HEADER})")
    try:
        text = head[start:start + hlen].decode("utf-8" if major == 3 else "latin-1")
        d = ast.literal_eval(text.strip())
    except (ValueError, SyntaxError, TypeError, RecursionError, MemoryError, OverflowError) as exc:
        raise CorruptDataError(path, f"{where} has an unreadable .npy header ({type(exc).__name__})") from None
    if not isinstance(d, dict) or sorted(d) != ["descr", "fortran_order", "shape"]:
        raise CorruptDataError(path, f"{where} has a .npy header without exactly descr, fortran_order and shape")
    shape, descr, fortran = d["shape"], d["descr"], d["fortran_order"]
    if not isinstance(shape, tuple) or not all(type(n) is int and 0 <= n < (1 << 48) for n in shape) \
            or len(shape) > 32:
        raise CorruptDataError(path, f"{where} has a bad .npy shape {str(shape)[:60]}")
    if not isinstance(fortran, bool) or not isinstance(descr, str):
        raise CorruptDataError(path, f"{where} has a bad .npy descr or fortran_order")
    try:
        dtype = np.dtype(descr)
    except (TypeError, ValueError, SyntaxError) as exc:
        raise CorruptDataError(path, f"{where} has an unknown .npy dtype {descr[:40]!r} ({exc})") from None
    if dtype.kind not in _KINDS or dtype.hasobject or dtype.fields is not None or dtype.subdtype is not None \
            or dtype.itemsize == 0:
        raise CorruptDataError(path, f"{where} holds {dtype} values; volumen reads numbers (and strings for text)")
    return dtype, shape, fortran, start + hlen


def _array(path, dtype, shape, fortran, have: int, where: str, load) -> np.ndarray:
    count = math.prod(shape)
    need = count * dtype.itemsize
    if need > lim.MAX_DATA_BYTES:
        raise DataSizeError(path, f"{where} states shape {shape}: {need} bytes, more than volumen's limit")
    if have < need:
        raise DataSizeError(path, f"{where} is too short: shape {shape} of {dtype} needs {need} bytes, "
                                  f"it holds {max(have, 0)}")
    flat = load(count)
    return flat.reshape(shape[::-1]).transpose() if fortran else flat.reshape(shape)


def read_npy(path) -> np.ndarray:
    """The array in the ``.npy`` file ``path`` (validated header, size checked before reading)."""
    with open(path, "rb") as f:
        head = f.read(_MAX_HEADER + 16)
        size = f.seek(0, 2)
    dtype, shape, fortran, offset = _header(path, head, path.name)
    return _array(path, dtype, shape, fortran, size - offset, path.name,
                  lambda n: np.fromfile(path, dtype=dtype, count=n, offset=offset))


def _member(path, blob: bytes, where: str) -> np.ndarray:
    dtype, shape, fortran, offset = _header(path, blob[:_MAX_HEADER + 16], where)
    return _array(path, dtype, shape, fortran, len(blob) - offset, where,
                  lambda n: np.frombuffer(blob, dtype=dtype, count=n, offset=offset))


def read_npz(path, wanted) -> tuple[list[str], dict[str, np.ndarray]]:
    """Names of all arrays in the archive and the arrays whose name is in ``wanted(names)``."""
    try:
        with zipfile.ZipFile(path) as z:
            infos = {i.filename[:-4] if i.filename.endswith(".npy") else i.filename: i for i in z.infolist()}
            names = list(infos)
            out = {}
            for name in wanted(names):
                info = infos[name]
                if info.file_size > lim.MAX_DATA_BYTES or \
                        info.file_size > _MAX_DEFLATE_RATIO * max(info.compress_size, 1) + (1 << 16):
                    raise DataSizeError(path, f"member {info.filename} claims {info.file_size} bytes from "
                                              f"{info.compress_size} stored")
                out[name] = _member(path, z.read(info), info.filename)
    except (zipfile.BadZipFile, zipfile.LargeZipFile, NotImplementedError, OSError, EOFError, zlib.error,
            RuntimeError, ValueError, UnicodeDecodeError) as exc:
        raise CorruptDataError(path, f"is not a readable .npz archive ({type(exc).__name__}: {exc})") from exc
    return names, out
