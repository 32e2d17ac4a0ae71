"""NumPy files (``.npy``, ``.npz``) and the JSON geometry record shared by the writers.

``.npy`` holds only an array ``[z, y, x]``; its geometry travels in a JSON sidecar
``<name>.npy.json`` (the *geometry record*, below). ``.npz`` holds the array
under ``data`` next to ``spacing`` ``(dz, dy, dx)`` mm, ``affine`` (4, 4) voxel
(i, j, k) -> RAS+ mm, and the strings ``modality``, ``units`` and ``name``.

The geometry record is one JSON object::

    {"format": "volumen-geometry", "version": 1,
     "spacing": [dz, dy, dx], "affine": [[...], [...], [...], [...]],
     "modality": "CT", "units": "HU", "name": "..."}

JSON writes Python floats with ``repr``, so float64 values come back exactly.
The NIfTI, NRRD and MetaImage writers store the same record in a field of
their own format, because their native geometry is either float32 (NIfTI's
sform) or split into direction and spacing (MetaImage), neither of which gives
the float64 affine back bit for bit. Readers use the record only when it agrees
with the file's native geometry (:func:`apply_record`), so a file edited by
another program keeps the geometry that program wrote.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..core import Volume
from ..errors import CorruptDataError, VolumeReadError
from ._npy_format import read_npy, read_npz

__all__ = ["read", "write", "geometry_record", "parse_record", "apply_record", "native", "spacing_of"]

RECORD_FORMAT = "volumen-geometry"


# -- helpers shared by the format modules --------------------------------------
def native(a: np.ndarray) -> np.ndarray:
    """``a`` in native byte order, C-contiguous (copied only when needed)."""
    a = np.asarray(a)
    if not a.dtype.isnative:
        a = a.astype(a.dtype.newbyteorder("="))
    return np.ascontiguousarray(a)


def spacing_of(affine: np.ndarray) -> tuple[float, float, float]:
    """``(dz, dy, dx)`` mm: lengths of the affine's columns k, j, i."""
    n = np.linalg.norm(np.asarray(affine, dtype=float)[:3, :3], axis=0)
    return float(n[2]), float(n[1]), float(n[0])


def geometry_record(volume: Volume) -> str:
    """The volume's geometry record as one line of JSON (floats exact)."""
    rec = {
        "format": RECORD_FORMAT, "version": 1,
        "spacing": [float(s) for s in volume.spacing],
        "affine": [[float(v) for v in row] for row in np.asarray(volume.affine, dtype=float)],
        "modality": str(volume.modality), "units": str(volume.units), "name": str(volume.name),
    }
    return json.dumps(rec, separators=(",", ":"))


def parse_record(text) -> dict | None:
    """The record in ``text`` (str or bytes, NUL padding allowed), or None if it is not one."""
    if isinstance(text, (bytes, bytearray)):
        text = bytes(text).rstrip(b"\x00").decode("utf-8", "replace")
    try:
        rec = json.loads(str(text).strip())
        if not isinstance(rec, dict) or rec.get("format") != RECORD_FORMAT:
            return None
        affine = np.array(rec["affine"], dtype=float)
        spacing = tuple(float(s) for s in rec["spacing"])
    except (ValueError, KeyError, TypeError):
        return None
    if affine.shape != (4, 4) or len(spacing) != 3:
        return None
    rec["affine"], rec["spacing"] = affine, spacing
    return rec


def apply_record(rec: dict | None, affine: np.ndarray, spacing, *, rtol: float, what: str,
                 warnings: list[str]) -> tuple[np.ndarray, tuple, dict]:
    """Choose between a geometry record and the file's native geometry.

    Parameters
    ----------
    rec : dict or None
        From :func:`parse_record`.
    affine : (4, 4) float
        The native voxel -> RAS+ mm affine read from the file.
    spacing : (3,) float, mm
        The native ``(dz, dy, dx)``.
    rtol : float
        Relative precision of the native geometry (``2**-23`` for float32 fields);
        the record is used when every affine entry agrees within
        ``4 * rtol * max(1, max|affine|)``.
    what : str
        Name of the native field, for the warning.
    warnings : list of str
        Receives a line when the record is ignored.

    Returns
    -------
    affine, spacing, extras
        The chosen geometry and ``{"modality", "units", "name"}`` from the record
        (empty without one).
    """
    if rec is None:
        return affine, tuple(spacing), {}
    extras = {k: str(rec[k]) for k in ("modality", "units", "name") if isinstance(rec.get(k), str)}
    tol = 4 * rtol * max(1.0, float(np.abs(affine).max()))
    if np.all(np.abs(rec["affine"] - affine) <= tol):
        return rec["affine"], rec["spacing"], extras
    warnings.append(f"the volumen geometry record disagrees with the {what} (the file was edited by "
                    f"another program?); using the {what}")
    return affine, tuple(spacing), extras


# -- .npy / .npz ----------------------------------------------------------------
def _sidecar(path: Path) -> Path:
    return path.with_name(path.name + ".json")


def _as_3d(path, a: np.ndarray, warnings: list[str]) -> np.ndarray:
    if a.ndim == 2:
        warnings.append(f"2-D array {a.shape} read as one slice (1, ny, nx)")
        return a[None]
    if a.ndim != 3:
        raise CorruptDataError(path, f"holds a {a.ndim}-D array of shape {a.shape}; a volume is 3-D [z, y, x]")
    if a.dtype.kind not in "biuf":
        raise CorruptDataError(path, f"holds {a.dtype} values; volumen reads bool, integer and float arrays")
    return a


def read(path, *, key: str | None = None) -> Volume:
    """Read a ``.npy`` (plus sidecar) or ``.npz`` file.

    Parameters
    ----------
    path : path
        ``.npy``: an array ``[z, y, x]``; geometry from ``<path>.json`` when present,
        otherwise 1 mm axis-aligned RAS with a warning in ``meta["warnings"]``.
        ``.npz``: arrays ``data`` (``[z, y, x]``), optional ``spacing`` ``(dz, dy, dx)`` mm,
        ``affine`` (4, 4) voxel (i, j, k) -> RAS+ mm, ``modality``, ``units``, ``name``.
    key : str, optional
        Name of the data array in an ``.npz`` (default ``data``, or the only array).

    Returns
    -------
    Volume
    """
    path = Path(path)
    warnings: list[str] = []
    if path.suffix.lower() != ".npz":
        return _from_npy(path, read_npy(path), warnings)

    def wanted(names):
        nonlocal key
        if key is None:
            key = "data" if "data" in names or len(names) != 1 else names[0]
        if key not in names:
            raise VolumeReadError(path, f"has no array {key!r}; its arrays are {names} (choose one with key=)")
        return [n for n in names if n in (key, "spacing", "affine", "modality", "units", "name")]

    _names, arrays = read_npz(path, wanted)
    data = _as_3d(path, arrays[key], warnings)
    spacing = _numbers(path, arrays.get("spacing"), (3,), "spacing")
    affine = _numbers(path, arrays.get("affine"), (4, 4), "affine")
    if spacing is None and affine is None:
        warnings.append("no spacing or affine stored: geometry unknown, 1 mm axis-aligned RAS assumed")
    if affine is not None and spacing is None:
        spacing = spacing_of(affine)
    text = {k: _text(arrays[k]) for k in ("modality", "units", "name") if k in arrays}
    return _volume(path, native(data), (1.0, 1.0, 1.0) if spacing is None else spacing, affine,
                   text, warnings, "npz")


def _text(a: np.ndarray) -> str:
    """A 0-d string array as text ("" for anything else, or characters that are not Unicode)."""
    if a.shape != () or a.dtype.kind not in "US":
        return ""
    raw = a.tobytes()
    if a.dtype.kind == "S":
        return raw.rstrip(b"\x00").decode("latin-1")
    return raw.decode("utf-32-be" if a.dtype.byteorder == ">" else "utf-32-le", "replace").rstrip("\x00")


def _numbers(path, a, shape, what):
    """``a`` as finite float64 of ``shape`` (None stays None)."""
    if a is None:
        return None
    if a.shape != shape or a.dtype.kind not in "biuf" or not np.all(np.isfinite(a)):
        raise CorruptDataError(path, f"its {what} array must be {shape} finite numbers, got {a.dtype} {a.shape}")
    return a.astype(np.float64)


def _from_npy(path: Path, data: np.ndarray, warnings: list[str]) -> Volume:
    data = _as_3d(path, data, warnings)
    side = _sidecar(path)
    if not side.exists():
        warnings.append(f"no sidecar {side.name}: geometry unknown, 1 mm axis-aligned RAS assumed")
        return _volume(path, native(data), (1.0, 1.0, 1.0), None, {}, warnings, "npy")
    rec = parse_record(side.read_bytes())
    if rec is None:
        raise CorruptDataError(side, f"is not a volumen geometry record (the sidecar of {path.name})")
    text = {k: str(rec[k]) for k in ("modality", "units", "name") if isinstance(rec.get(k), str)}
    return _volume(path, native(data), rec["spacing"], rec["affine"], text, warnings, "npy+json")


def _volume(path, data, spacing, affine, text, warnings, kind) -> Volume:
    try:
        return Volume(data, spacing=np.asarray(spacing, dtype=float), affine=affine,
                      modality=text.get("modality") or "OT", units=text.get("units", ""),
                      name=text.get("name") or Path(path).name.split(".")[0],
                      meta={"warnings": warnings, "numpy_kind": kind})
    except ValueError as exc:
        raise CorruptDataError(path, f"has inconsistent geometry: {exc}") from exc


def write(volume: Volume, path) -> None:
    """Write ``.npy`` (+ ``<path>.json`` geometry record) or ``.npz``; dtype, spacing and affine exact."""
    path = Path(path)
    if path.suffix.lower() == ".npz":
        with open(path, "wb") as f:  # an open file keeps numpy from appending a suffix
            np.savez(f, data=volume.data, spacing=np.asarray(volume.spacing, dtype=np.float64),
                     affine=np.asarray(volume.affine, dtype=np.float64), modality=np.array(str(volume.modality)),
                     units=np.array(str(volume.units)), name=np.array(str(volume.name)))
        return
    with open(path, "wb") as f:
        np.save(f, volume.data, allow_pickle=False)
    _sidecar(path).write_text(geometry_record(volume) + "\n", encoding="utf-8")
