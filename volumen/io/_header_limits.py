"""Checks every reader applies to header values before it trusts them.

* **Sizes.** The bytes a header asks for are computed with Python integers and
  compared with :data:`MAX_DATA_BYTES` and with the real size of the data it points
  at *before* anything is allocated (:func:`need_bytes`, :func:`check_available`);
  compressed data is inflated with a bound of the expected size plus one byte
  (:func:`inflate`), so a header can never make volumen allocate more than the data
  holds, nor more than the limit.
* **Data files.** A file named by a header (MetaImage ``ElementDataFile``, NRRD
  ``data file``, their list and pattern forms) must lie in the header's folder
  (:func:`data_file`) unless the caller passed ``allow_outside=True``.
* **Libraries that trust lengths.** :func:`open_bounded` opens a file whose
  ``read(n)`` never asks for more than the bytes left, so a library reading an element
  length from the file (pydicom) cannot allocate gigabytes for a damaged length field.
* **Numbers and patterns.** :func:`to_int` / :func:`to_floats` turn header text into
  bounded numbers; :func:`expand_pattern` expands a ``%d`` file-name pattern without
  Python's ``%`` operator, after checking how many names it would produce.
"""

from __future__ import annotations

import bz2
import io
import math
import os
import re
import zlib
from pathlib import Path

from ..errors import CorruptDataError, DataSizeError, MissingPathError, OutsideFolderError

__all__ = ["MAX_DATA_BYTES", "MAX_FILES", "open_bounded", "need_bytes", "check_available", "data_file", "inflate",
           "to_int", "to_floats", "expand_pattern"]

MAX_DATA_BYTES = 1 << 36  # 64 GiB: no header may ask for more decoded data than this
MAX_FILES = 1 << 16  # data files one header may list
_CHUNK = 1 << 22


class _BoundedReader(io.BufferedReader):
    """A binary file whose ``read(n)`` is clamped to the bytes left in the file."""

    def __init__(self, path):
        super().__init__(io.FileIO(os.fspath(path)))
        self._size = os.fstat(self.fileno()).st_size

    def read(self, n: int | None = -1) -> bytes:
        if n is not None and n > 0:
            n = max(0, min(n, self._size - self.tell()))
        return super().read(n)


def open_bounded(path) -> io.BufferedReader:
    """Open ``path`` for reading such that ``read(n)`` allocates at most what the file still holds.

    For readers that take a length from the file and call ``read(length)``:
    ``with open_bounded(path) as f: ds = pydicom.dcmread(f)``.
    """
    return _BoundedReader(path)


def need_bytes(path, sizes, itemsize: int, what: str = "the header") -> int:
    """Bytes of ``prod(sizes) * itemsize``, checked: every size >= 1 and the total within the limit."""
    sizes = [int(n) for n in sizes]
    if not sizes or min(sizes) < 1:
        raise CorruptDataError(path, f"{what} gives sizes {sizes}; each must be >= 1")
    total = math.prod(sizes) * int(itemsize)
    if total > MAX_DATA_BYTES:
        raise DataSizeError(path, f"{what} asks for {total} bytes of data (sizes {sizes}), more than volumen's "
                                  f"limit of {MAX_DATA_BYTES} bytes")
    return total


def check_available(path, target: Path, start: int, need: int) -> int:
    """Bytes of ``target`` after ``start``; raises DataSizeError when fewer than ``need``."""
    have = os.path.getsize(target) - start
    if have < need:
        raise DataSizeError(path, f"data too short: the header needs {need} bytes from {target.name}, "
                                  f"it holds {max(have, 0)}")
    return have


def data_file(path, name: str, allow_outside: bool = False) -> Path:
    """The file ``name`` named by the header ``path``, resolved against the header's folder.

    Raises OutsideFolderError for a file outside that folder (unless ``allow_outside``),
    MissingPathError for a missing file, CorruptDataError for a folder or unusable name.
    """
    folder = Path(path).resolve().parent
    try:
        target = (folder / name).resolve() if name.strip() else folder
        is_dir, is_file = target.is_dir(), target.is_file()
    except (OSError, ValueError) as exc:
        raise CorruptDataError(path, f"the data file name {name[:200]!r} is unusable ({exc})") from exc
    if not allow_outside and not target.is_relative_to(folder):
        raise OutsideFolderError(path, f"the header names the data file {name[:200]!r}, outside its folder "
                                       f"{folder} (load with allow_outside=True to read it)")
    if is_dir:
        raise CorruptDataError(path, f"the data file {name[:200]!r} named by the header is a folder")
    if not is_file:
        raise MissingPathError(path, f"the data file {name[:200]!r} named by the header does not exist")
    return target


def inflate(path, blob: bytes, expected: int, codec: str, where: str, *, exact: bool = True) -> bytes:
    """Decompress ``blob`` (``codec`` "zlib", "gzip" or "bzip2") to exactly ``expected`` bytes
    (at most ``expected`` unless ``exact``).

    Never produces more than ``expected + 1`` bytes; raises CorruptDataError for a
    broken stream and DataSizeError when it inflates to another size.
    """
    if codec == "bzip2":
        engine = bz2.BZ2Decompressor()
    else:
        engine = zlib.decompressobj(zlib.MAX_WBITS | (16 if codec == "gzip" else 0))
    out = bytearray()
    try:
        for i in range(0, len(blob), _CHUNK):
            out += engine.decompress(blob[i:i + _CHUNK], expected + 1 - len(out))  # bounded output
            if len(out) > expected or engine.eof:
                break
    except (zlib.error, OSError, ValueError, EOFError) as exc:
        raise CorruptDataError(path, f"{codec} data in {where} is broken ({exc})") from exc
    if len(out) > expected or (exact and len(out) != expected) or not engine.eof:
        raise DataSizeError(path, f"{codec} data in {where} inflates to {'more than ' if len(out) > expected else ''}"
                                  f"{min(len(out), expected)} bytes{'' if engine.eof else ' (cut short)'}; "
                                  f"the header needs {expected}")
    return bytes(out)


def to_int(path, field: str, text, lo: int = 0, hi: int = 1 << 62) -> int:
    """``text`` as an integer in ``[lo, hi]``; CorruptDataError naming ``field`` otherwise."""
    try:
        value = int(str(text).strip())
    except ValueError:
        raise CorruptDataError(path, f"header field {field} = {str(text)[:60]!r} is not an integer") from None
    if not lo <= value <= hi:
        raise CorruptDataError(path, f"header field {field} = {value} is outside {lo}..{hi}")
    return value


def to_floats(path, field: str, text: str, n: int) -> list[float]:
    """``n`` finite numbers from the whitespace-separated ``text``."""
    parts = str(text).split()
    try:
        values = [float(p) for p in parts]
    except ValueError:
        values = []
    if len(values) != n or not all(math.isfinite(v) for v in values):
        raise CorruptDataError(path, f"header field {field} = {str(text)[:80]!r} is not {n} finite numbers")
    return values


_PATTERN = re.compile(r"%(0?\d{0,3})d")


def expand_pattern(path, pattern: str, lo: int, hi: int, step: int, count: int) -> list[str]:
    """Names ``pattern % i`` for ``i = lo, lo + step, ... <= hi`` (or >= hi for a negative step).

    ``pattern`` must hold exactly one ``%d`` conversion (``%03d`` style) and no other
    ``%`` but ``%%``; the range must give exactly ``count`` names.
    """
    if step == 0 or (hi - lo) * step < 0:
        raise CorruptDataError(path, f"file pattern range {lo}..{hi} step {step} gives no files")
    n = (hi - lo) // step + 1
    if n != count:
        raise DataSizeError(path, f"file pattern {pattern[:80]!r} {lo} {hi} {step} gives {n} files, the sizes "
                                  f"need {count}")
    rest = _PATTERN.sub("", pattern).replace("%%", "")
    if len(_PATTERN.findall(pattern)) != 1 or "%" in rest:
        raise CorruptDataError(path, f"file pattern {pattern[:80]!r} must hold one integer conversion like %03d")
    m = _PATTERN.search(pattern)
    width = m.group(1)
    head, tail = pattern[:m.start()].replace("%%", "%"), pattern[m.end():].replace("%%", "%")
    fmt = "{:" + (width if width else "") + "d}"
    return [head + fmt.format(lo + i * step) + tail for i in range(n)]
