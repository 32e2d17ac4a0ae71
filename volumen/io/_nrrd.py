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

import bz2
import os
import re
import zlib
from pathlib import Path

import numpy as np

from ..core import Volume
from ..errors import CorruptDataError, DataSizeError, MissingPathError, VolumeWriteError
from ._numpy import apply_record, geometry_record, native, parse_record, spacing_of

__all__ = ["read", "write"]

_TO_RAS = {"RAS": (1.0, 1.0, 1.0), "LPS": (-1.0, -1.0, 1.0), "LAS": (-1.0, 1.0, 1.0)}
_SPACES = {"right-anterior-superior": "RAS", "ras": "RAS", "left-posterior-superior": "LPS", "lps": "LPS",
           "left-anterior-superior": "LAS", "las": "LAS", "scanner-xyz": None, "3d-right-handed": None,
           "3d-left-handed": None}
_RECORD_KEY = "volumen"


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


def _data_files(path: Path, header: dict, names: list[str] | None) -> tuple[list[Path], int] | None:
    """Detached list-form files and their subdim, or None for a single (or attached) data file."""
    dim = int(header["dimension"])
    if names is not None:
        sub = header.pop("volumen list subdim", "")
        files = names
    else:
        value = header.get("data file", header.get("datafile"))
        parts = value.split() if value else []
        if len(parts) < 4 or "%" not in parts[0]:
            return None
        try:
            lo, hi, step = (int(v) for v in parts[1:4])
        except ValueError as exc:
            raise CorruptDataError(path, f"bad 'data file' list form {value!r} ({exc})") from exc
        if step == 0 or (hi - lo) * step < 0:
            raise CorruptDataError(path, f"bad 'data file' list form {value!r}: step {step} never reaches {hi}")
        files = [parts[0] % i for i in range(lo, hi + (1 if step > 0 else -1), step)]
        sub = parts[4] if len(parts) > 4 else ""
    subdim = int(sub) if str(sub).strip() else dim - 1
    if not 1 <= subdim <= dim:
        raise CorruptDataError(path, f"'data file' subdim {subdim} is outside 1..{dim}")
    return [Path(f) if os.path.isabs(f) else path.parent / f for f in files], subdim


def _decode(path: Path, fname: Path, header: dict, count: int | None) -> np.ndarray:
    """The samples of one data file of a list form (``count`` of them, or all)."""
    dtype, enc = header["_dtype"], header["encoding"].lower()
    if not fname.exists():
        raise MissingPathError(path, f"the data file {fname.name!r} named by the header does not exist")
    with open(fname, "rb") as f:
        for _ in range(int(header.get("line skip", header.get("lineskip", 0)))):
            f.readline()
        skip = int(header.get("byte skip", header.get("byteskip", 0)))
        if skip > 0 and enc in ("raw",):
            f.seek(skip, os.SEEK_CUR)
        body = f.read()
    try:
        if enc in ("gzip", "gz"):
            body = zlib.decompressobj(zlib.MAX_WBITS | 16).decompress(body)
        elif enc in ("bzip2", "bz2"):
            body = bz2.decompress(body)
    except (zlib.error, OSError, ValueError) as exc:
        raise CorruptDataError(path, f"data file {fname.name} is not valid {enc} ({exc})") from exc
    if enc in ("ascii", "text", "txt"):
        values = body.decode("latin-1").split()
        out = np.array(values, dtype=np.float64 if dtype.kind == "f" else np.int64).astype(dtype)
    else:
        if enc not in ("raw", "gzip", "gz", "bzip2", "bz2"):
            raise CorruptDataError(path, f"unsupported NRRD encoding {enc!r}")
        if skip == -1 and count is not None:
            body = body[len(body) - count * dtype.itemsize:]
        elif skip > 0 and enc != "raw":
            body = body[skip:]
        usable = len(body) - len(body) % dtype.itemsize
        out = np.frombuffer(body[:usable], dtype=dtype)
    if count is not None and out.size != count:
        raise DataSizeError(path, f"data file {fname.name} holds {out.size} samples, the header needs {count}")
    return out


def _read_data(path: Path, header: dict, offset: int, names: list[str] | None) -> np.ndarray:
    import nrrd

    sizes = [int(n) for n in header["sizes"]]
    total = int(np.prod(sizes))
    listing = _data_files(path, header, names)
    if listing is not None:
        files, subdim = listing
        per = int(np.prod(sizes[:subdim]))
        parts = [_decode(path, f, header, per if subdim < len(sizes) else None) for f in files]
        flat = np.concatenate(parts) if parts else np.zeros(0, header["_dtype"])
        if flat.size != total:
            raise DataSizeError(path, f"the {len(files)} data files hold {flat.size} samples, the header "
                                      f"needs {total} (sizes {sizes})")
        return flat.reshape(sizes[::-1])
    datafile = header.get("data file", header.get("datafile"))
    if datafile is not None:
        target = Path(datafile) if os.path.isabs(datafile) else path.parent / datafile
        if not target.exists():
            raise MissingPathError(path, f"the data file {datafile!r} named by the header does not exist")
        start = 0
    else:
        target, start = path, offset
    skip = int(header.get("byte skip", header.get("byteskip", 0)))
    lskip = int(header.get("line skip", header.get("lineskip", 0)))
    if header["encoding"].lower() == "raw" and skip >= 0 and lskip == 0:
        need = total * header["_dtype"].itemsize
        have = os.path.getsize(target) - start - skip
        if have != need:
            raise DataSizeError(path, f"raw data too {'short' if have < need else 'long'}: sizes {sizes} of "
                                      f"{header['type']} need {need} bytes, {target.name} has {max(have, 0)}")
    try:
        with open(path, "rb") as fh:
            fh.seek(offset)
            return nrrd.read_data(header, fh, os.fspath(path), index_order="C")
    except (zlib.error, EOFError, OSError) as exc:
        raise CorruptDataError(path, f"compressed data is broken ({exc})") from exc
    except Exception as exc:  # NRRDError and numpy's ValueError
        m = re.search(r"dimensions: (-?\d+)-(-?\d+)=", str(exc))
        if m:
            raise DataSizeError(path, f"data holds {m.group(2)} samples, the header needs {m.group(1)} "
                                      f"(sizes {sizes})") from exc
        raise CorruptDataError(path, f"data could not be decoded ({exc})") from exc


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


def read(path) -> Volume:
    """Read a NRRD file (attached data, or a ``.nhdr`` with detached data in any form).

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
    except ValueError as exc:
        raise CorruptDataError(path, f"has geometry volumen cannot use: {exc}") from exc
    data = _read_data(path, header, offset, names)
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
