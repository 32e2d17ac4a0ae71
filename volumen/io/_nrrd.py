"""NRRD (``.nrrd``, ``.nhdr`` + detached data) through pynrrd, plus the list forms of detached data.

pynrrd 1.1 parses the header fields, decodes one attached or detached data file
(encodings raw, gzip, bzip2, ascii; either endianness; ``byte skip``/``line skip``)
and writes. It does not read the two multi-file forms of ``data file``, which
are handled here:

* ``data file: <pattern> <min> <max> <step> [<subdim>]`` -- a printf-style pattern
  (``slice%03d.raw 1 10 1``) expanded for ``min, min + step, ... <= max``;
* ``data file: LIST [<subdim>]`` -- the file names follow, one per line, to the
  end of the header.

Each file holds the samples of ``subdim`` fastest axes (default ``dimension - 1``,
i.e. one slice each); their concatenation is the whole array. ``byte skip`` and
``line skip`` apply to every file.

Arrays: NRRD lists ``sizes`` fastest axis first; read in C order the array is
``[z, y, x]`` for sizes ``(nx, ny, nz)``, which is what ``Volume`` wants.

Geometry: ``space directions`` (one column per domain axis) and ``space origin``
in the declared ``space``. RAS (``right-anterior-superior``, ``RAS``) is kept,
LPS (``left-posterior-superior``, ``LPS``) and LAS are flipped to RAS+.
``scanner-xyz``, ``3D-right-handed``, ``3D-left-handed`` and files with only
``spacings`` have no patient frame; like ITK they are taken as LPS, with a
warning. Three spatial axes are required; one more, non-spatial axis (a vector,
list or time axis) is reduced to its first sample, with a warning. The writer uses ``left-posterior-superior`` with
17-digit numbers (exact float64) and adds the JSON geometry record (see
:mod:`volumen.io._numpy`) as the key/value ``volumen:=...`` so that spacing is
exact too.
"""

from __future__ import annotations

import math
import os
import re
from pathlib import Path

import numpy as np

from ..core import Volume
from ..errors import CorruptDataError, DataSizeError, VolumeWriteError
from . import _header_limits as lim
from ._numpy import apply_record, geometry_record, native, parse_record, spacing_of

__all__ = ["read", "write"]

_TO_RAS = {"RAS": (1.0, 1.0, 1.0), "LPS": (-1.0, -1.0, 1.0), "LAS": (-1.0, 1.0, 1.0)}
_SPACES = {"right-anterior-superior": "RAS", "ras": "RAS", "left-posterior-superior": "LPS", "lps": "LPS",
           "left-anterior-superior": "LAS", "las": "LAS", "scanner-xyz": None, "3d-right-handed": None,
           "3d-left-handed": None}
_RECORD_KEY = "volumen"
_CODECS = {"gzip": "gzip", "gz": "gzip", "bzip2": "bzip2", "bz2": "bzip2"}


def _read_header(path: Path) -> tuple[list[str], int, list[str] | None]:
    """Header lines (magic first, without list file names), data offset, LIST file names or None."""
    lines: list[str] = []
    names: list[str] | None = None
    pos = 0
    with open(path, "rb") as f:
        magic = f.readline(64)
        if not magic.startswith(b"NRRD000"):
            raise CorruptDataError(path, "is not a NRRD file (the first line is not 'NRRD000x')")
        pos = len(magic)
        lines.append(magic.decode("latin-1").strip())
        while True:
            raw = f.readline(1 << 20)
            if not raw:
                break
            pos += len(raw)
            text = raw.decode("latin-1").rstrip("\r\n")
            if names is not None:
                if text.strip():
                    names.append(text.strip())
                continue
            if not text.strip():
                break
            if re.match(r"^data ?file\s*:\s*LIST\b", text):
                names = []
                subdim = text.split(":", 1)[1].split()[1:]
                lines.append(f"volumen list subdim:={subdim[0] if subdim else ''}")
                continue
            lines.append(text)
    return lines, pos, names


def _parse(path: Path, lines: list[str]) -> dict:
    import nrrd

    try:
        header = nrrd.read_header(lines)
        for field in ("type", "dimension", "sizes", "encoding"):
            if field not in header:
                raise ValueError(f"the header has no '{field}' field")
        if header["dimension"] != len(header["sizes"]):
            raise ValueError(f"dimension {header['dimension']} but {len(header['sizes'])} sizes")
        header["_dtype"] = nrrd.reader._determine_datatype(header)
    except Exception as exc:  # pynrrd raises NRRDError, ValueError, KeyError for bad fields
        raise CorruptDataError(path, f"has a broken NRRD header ({exc})") from exc
    return header


def _sources(path: Path, header: dict, names: list[str] | None, offset: int,
             allow_outside: bool) -> tuple[list[tuple[Path, int]], int | None]:
    """(file, first byte) of each data file, and the samples each holds (None: slabs of any thickness)."""
    sizes = [int(n) for n in header["sizes"]]
    dim, total = len(sizes), math.prod(sizes)
    value = header.get("data file", header.get("datafile"))
    if names is None and value is None:
        return [(path, offset)], total
    parts = str(value).split() if names is None else []
    if names is None and (len(parts) < 4 or "%" not in parts[0]):
        return [(lim.data_file(path, str(value), allow_outside), 0)], total
    sub = header.pop("volumen list subdim", "") if names is not None else (parts[4] if len(parts) > 4 else "")
    subdim = lim.to_int(path, "data file subdim", sub if str(sub).strip() else dim - 1, 1, dim)
    count = math.prod(sizes[subdim:])
    if count > lim.MAX_FILES:
        raise CorruptDataError(path, f"'data file' would need {count} files (more than {lim.MAX_FILES})")
    if names is not None:
        if len(names) != count and subdim < dim or len(names) > lim.MAX_FILES:
            raise DataSizeError(path, f"'data file: LIST' names {len(names)} files, sizes {sizes} with subdim "
                                      f"{subdim} need {count}")
    else:
        lo, hi, step = (lim.to_int(path, "data file", t, -(1 << 62)) for t in parts[1:4])
        names = lim.expand_pattern(path, parts[0], lo, hi, step, count)
    return [(lim.data_file(path, n, allow_outside), 0) for n in names], (total // count if subdim < dim else None)


def _skip_lines(path: Path, f, target: Path, n: int) -> None:
    for _ in range(n):
        if not f.readline(1 << 20):
            raise DataSizeError(path, f"line skip {n} passes the end of {target.name}")


def _decode(path: Path, target: Path, start: int, count: int, header: dict, single: bool,
            exact: bool = True) -> np.ndarray:
    """``count`` samples (at most ``count`` unless ``exact``) from ``target`` at ``start``, after the
    header's line and byte skips."""
    dtype, enc = header["_dtype"], str(header["encoding"]).lower()
    lskip = lim.to_int(path, "line skip", header.get("line skip", header.get("lineskip", 0)), 0, 1 << 40)
    bskip = lim.to_int(path, "byte skip", header.get("byte skip", header.get("byteskip", 0)), -1, 1 << 40)
    nbytes = count * dtype.itemsize
    with open(target, "rb") as f:
        f.seek(start)
        _skip_lines(path, f, target, lskip)
        pos = f.tell()
        if enc == "raw":
            pos = os.path.getsize(target) - nbytes if bskip == -1 else pos + bskip
            if not exact:
                have = os.path.getsize(target) - pos
                if have > nbytes:
                    raise DataSizeError(path, f"the data files hold more than the {count} samples of sizes "
                                              f"{header['sizes']} ({target.name} alone has {have} bytes)")
                count, nbytes = max(have, 0) // dtype.itemsize, max(have, 0) - max(have, 0) % dtype.itemsize
            have = lim.check_available(path, target, pos, nbytes)
            if have > nbytes and single and bskip >= 0 and lskip == 0:
                raise DataSizeError(path, f"raw data too long: sizes {header['sizes']} of {header['type']} need "
                                          f"{nbytes} bytes, {target.name} has {have}")
            return np.fromfile(target, dtype=dtype, count=count, offset=pos)
        blob = f.read()
    if enc in _CODECS:
        if bskip < 0:
            raise CorruptDataError(path, f"byte skip {bskip} is only allowed with raw encoding")
        body = lim.inflate(path, blob, bskip + nbytes, _CODECS[enc], target.name, exact=exact)[bskip:]
        body = body[:len(body) - len(body) % dtype.itemsize]
        return np.frombuffer(body, dtype=dtype)
    if enc not in ("ascii", "text", "txt"):
        raise CorruptDataError(path, f"unsupported NRRD encoding {enc!r}; volumen reads raw, gzip, bzip2 and ascii")
    tokens = blob.split(maxsplit=count)[:count + 1] if count <= len(blob) or not exact else []
    if len(tokens) > count:
        raise DataSizeError(path, f"ASCII data in {target.name} holds more than the {count} values needed")
    if len(tokens) < count and exact:
        raise DataSizeError(path, f"ASCII data in {target.name} holds fewer than the {count} values needed")
    try:
        return np.array(tokens, dtype=np.float64 if dtype.kind == "f" else np.int64).astype(dtype)
    except (ValueError, OverflowError) as exc:
        raise CorruptDataError(path, f"ASCII data in {target.name} holds a bad number ({exc})") from exc


def _read_data(path: Path, header: dict, offset: int, names: list[str] | None, allow_outside: bool) -> np.ndarray:
    sizes = [int(n) for n in header["sizes"]]
    lim.need_bytes(path, sizes, header["_dtype"].itemsize, "sizes")
    sources, per = _sources(path, header, names, offset, allow_outside)
    total, parts = math.prod(sizes), []
    for f, s in sources:
        left = total - sum(p.size for p in parts)
        parts.append(_decode(path, f, s, left if per is None else per, header, len(sources) == 1, per is not None))
    flat = np.concatenate(parts)
    if flat.size != total:
        raise DataSizeError(path, f"the {len(sources)} data files hold {flat.size} samples, the header needs "
                                  f"{total} (sizes {sizes})")
    return flat.reshape(sizes[::-1])


def _geometry(header: dict, warnings: list[str]) -> tuple[np.ndarray, list[int]]:
    """RAS+ affine and the array axes (C order) that are spatial."""
    dim = int(header["dimension"])
    space = header.get("space")
    code = _SPACES.get(str(space).lower(), "?") if space is not None else None
    if space is not None and code == "?":
        raise ValueError(f"unsupported space {space!r}; volumen reads {sorted(set(_SPACES))}")
    dirs = header.get("space directions")
    if dirs is not None:
        dirs = np.asarray(dirs, dtype=float)
        spatial = [a for a in range(dim) if np.all(np.isfinite(dirs[a]))]
        origin = np.asarray(header.get("space origin", np.zeros(dirs.shape[1])), dtype=float)
        if dirs.shape[1] != 3 or len(spatial) != 3:
            raise ValueError(f"needs three spatial axes in 3-D space, got space directions {dirs.tolist()}")
        columns = dirs[spatial].T
    else:
        spacings = np.asarray(header.get("spacings", [np.nan] * dim), dtype=float)
        kinds = [k.lower() for k in header.get("kinds", ["domain"] * dim)]
        spatial = [a for a in range(dim) if kinds[a] in ("domain", "space")] if dim > 3 else list(range(dim))
        if len(spatial) != 3:
            raise ValueError(f"needs three spatial axes, got kinds {kinds}")
        steps = np.where(np.isfinite(spacings[spatial]), spacings[spatial], 1.0)
        columns = np.diag(steps)  # a negative spacing is an axis running the other way, kept
        mins = np.asarray(header.get("axis mins", header.get("axismins", [0.0] * dim)), dtype=float)
        origin = np.where(np.isfinite(mins[spatial]), mins[spatial], 0.0)
        # 'axis mins' is a cell's edge for axes declared cell-centred: the first voxel's centre is half a
        # spacing further along the axis (undeclared centering: the first sample itself, as ITK reads it)
        centerings = [str(c).lower() for c in header.get("centerings", header.get("centers", ["???"] * dim))]
        half = np.array([0.5 if centerings[a] == "cell" else 0.0 for a in spatial])
        has_min = np.isfinite(mins[spatial])
        origin = origin + np.where(has_min, half * steps, 0.0)
        warnings.append("no 'space directions': orientation unknown, axes taken as LPS like ITK")
    if code is None and dirs is not None:
        warnings.append(f"space {space or '(none)'!r} has no patient frame: taken as LPS like ITK")
    flip = np.array(_TO_RAS[code or "LPS"])
    affine = np.eye(4)
    affine[:3, :3] = flip[:, None] * columns
    affine[:3, 3] = flip * origin
    return affine, [dim - 1 - a for a in spatial]


def read(path, *, allow_outside: bool = False) -> Volume:
    """Read a NRRD file (attached data, or a ``.nhdr`` with detached data in any form).

    ``allow_outside``: read data files the header names outside its own folder
    (refused by default).

    Returns
    -------
    Volume
        Data ``[z, y, x]`` (NRRD sizes ``(nx, ny, nz)``) in its stored type, native
        byte order; affine voxel (i, j, k) -> RAS+ mm.
    """
    path = Path(path)
    lines, offset, names = _read_header(path)
    header = _parse(path, lines)
    warnings: list[str] = []
    try:
        affine, axes = _geometry(header, warnings)
    except (ValueError, IndexError, TypeError) as exc:
        raise CorruptDataError(path, f"has geometry volumen cannot use: {exc}") from exc
    data = _read_data(path, header, offset, names, allow_outside)
    if data.ndim > 3:
        other = [a for a in range(data.ndim) if a not in axes]
        warnings.append(f"{data.ndim}-D data: non-spatial axis reduced to its first sample")
        data = data[tuple(0 if a in other else slice(None) for a in range(data.ndim))]
    rec = parse_record(header.get(_RECORD_KEY)) if header.get(_RECORD_KEY) else None
    affine, spacing, extras = apply_record(rec, affine, spacing_of(affine), rtol=1e-12,
                                           what="space directions", warnings=warnings)
    meta = {"warnings": warnings, "nrrd_space": header.get("space", ""), "nrrd_encoding": header["encoding"]}
    try:
        return Volume(native(data), spacing=spacing, affine=affine, modality=extras.get("modality") or "OT",
                      units=extras.get("units", header.get("sample units", "")),
                      name=extras.get("name") or path.name.split(".")[0], meta=meta)
    except ValueError as exc:
        raise CorruptDataError(path, f"has unusable geometry: {exc}") from exc


def write(volume: Volume, path, *, encoding: str = "raw") -> None:
    """Write ``.nrrd`` (or ``.nhdr`` + ``.raw``), ``encoding`` ``"raw"`` or ``"gzip"``.

    Data ``[z, y, x]`` is written in C order (sizes ``(nx, ny, nz)``) in its dtype;
    space ``left-posterior-superior``, directions and origin with 17 digits.
    """
    import nrrd

    if encoding not in ("raw", "gzip"):
        raise ValueError(f"encoding must be 'raw' or 'gzip', got {encoding!r}")
    path = Path(path)
    lps = np.diag(_TO_RAS["LPS"]) @ np.asarray(volume.affine, dtype=np.float64)[:3]
    header = {
        "encoding": encoding, "space": "left-posterior-superior",
        "kinds": ["domain"] * 3, "space directions": lps[:, :3].T.copy(), "space origin": lps[:, 3].copy(),
        _RECORD_KEY: geometry_record(volume),
    }
    if volume.units:
        header["sample units"] = str(volume.units)
    try:
        nrrd.write(os.fspath(path), np.ascontiguousarray(volume.data), header, index_order="C",
                   compression_level=6)
    except OSError:
        raise
    except Exception as exc:
        raise VolumeWriteError(path, f"pynrrd could not write it ({exc})") from exc
