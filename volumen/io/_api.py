"""``load`` and ``save``: find the format, call its module, apply the shared checks.

Each format lives in its own module with ``read(path, **options) -> Volume`` and,
where writable, ``write(volume, path) -> None``. This module only picks the
module (by folder, suffix or magic bytes) and applies what every format shares:
the non-finite value policy, ``resample=True`` and the ``source`` entry in meta.
"""

from __future__ import annotations

import importlib
import inspect
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Literal

import numpy as np

from ..core import Volume, is_chunked
from ..errors import (
    DataSizeError,
    MissingPathError,
    NonFiniteValuesError,
    UnexpectedReadError,
    UnknownFormatError,
    VolumenError,
    VolumeReadError,
    VolumeWriteError,
)

__all__ = ["load", "save", "detect_format", "READ_FORMATS", "WRITE_FORMATS"]

# format name -> (module, suffixes)
READ_FORMATS: dict[str, tuple[str, tuple[str, ...]]] = {
    "dicom": ("_dicom", (".dcm", ".dicom", ".ima")),
    "nifti": ("_nifti", (".nii", ".nii.gz", ".img", ".hdr")),
    "nrrd": ("_nrrd", (".nrrd", ".nhdr")),
    "metaimage": ("_metaimage", (".mha", ".mhd")),
    "vtk": ("_vtk", (".vtk",)),
    "numpy": ("_numpy", (".npy", ".npz")),
    "raw": ("_raw", (".raw", ".bin")),
    "zarr": ("_zarr", (".zarr",)),
}
WRITE_FORMATS = ("nifti", "nrrd", "metaimage", "numpy", "zarr")

NonFinitePolicy = Literal["error", "keep", "zero", "min"]


def _suffix(path: Path) -> str:
    name = path.name.lower()
    for double in (".nii.gz",):
        if name.endswith(double):
            return double
    return path.suffix.lower()


def _is_dicom_file(path: Path) -> bool:
    try:
        with open(path, "rb") as f:
            head = f.read(132)
    except OSError:
        return False
    return len(head) >= 132 and head[128:132] == b"DICM"


def detect_format(path) -> str:
    """Name of the format of ``path`` (a file, a folder, or a list of files).

    A folder named ``*.zarr`` or holding Zarr metadata is Zarr; another folder,
    a list of files and a file with the ``DICM`` preamble are DICOM;
    otherwise the suffix decides. Raises :class:`UnknownFormatError` listing the
    known suffixes.
    """
    if isinstance(path, (list, tuple)):
        return "dicom"
    p = Path(path)
    if p.is_dir():
        return "zarr" if _suffix(p) == ".zarr" or (p / "zarr.json").exists() or (p / ".zgroup").exists() \
            or (p / ".zarray").exists() else "dicom"
    suf = _suffix(p)
    for name, (_mod, suffixes) in READ_FORMATS.items():
        if suf in suffixes:
            return name
    if _is_dicom_file(p):
        return "dicom"
    known = ", ".join(s for _m, sx in READ_FORMATS.values() for s in sx)
    raise UnknownFormatError(p, f"unknown volume format {suf or '(no suffix)'!r}; volumen reads {known} "
                                "and DICOM folders (raw files need shape=, dtype= and spacing=)")


def _module(fmt: str):
    return importlib.import_module(f"{__package__}.{READ_FORMATS[fmt][0]}")


def _apply_nonfinite(vol: Volume, policy: NonFinitePolicy, path) -> Volume:
    d = vol.data
    if not np.issubdtype(d.dtype, np.floating) or is_chunked(d):  # a chunked volume is read as it is asked for
        return vol
    bad = ~np.isfinite(d)
    n_bad = int(bad.sum())
    if n_bad == 0:
        return vol
    msg = f"{n_bad} of {d.size} voxels are NaN or infinite"
    if policy == "error":
        raise NonFiniteValuesError(path, msg + " (load with nonfinite='zero', 'min' or 'keep' to accept them)")
    if policy == "keep":
        vol.meta["warnings"].append(msg + "; kept as they are")
        return vol
    finite = d[~bad]
    fill = 0.0 if policy == "zero" or finite.size == 0 else float(finite.min())
    data = d.copy()
    data[bad] = fill
    vol.meta["warnings"].append(msg + f"; replaced by {fill:g}")
    vol.data = np.ascontiguousarray(data)
    return vol


def _check_options(func, fmt: str, path, options: dict) -> None:
    """Unknown reader options are a clear VolumeReadError, not a bare TypeError."""
    params = inspect.signature(func).parameters
    if any(p.kind is inspect.Parameter.VAR_KEYWORD for p in params.values()):
        return
    accepted = [n for n, p in params.items() if p.kind is inspect.Parameter.KEYWORD_ONLY
                or (p.kind is inspect.Parameter.POSITIONAL_OR_KEYWORD and n != "path")]
    unknown = sorted(set(options) - set(accepted))
    if unknown:
        raise VolumeReadError(path, f"the {fmt} reader does not take option(s) {', '.join(unknown)}; "
                                    f"it takes: {', '.join(accepted) or 'none'}")


def _read(mod, path, options: dict) -> Volume:
    """``mod.read`` with the last-resort net: whatever a reader did not anticipate becomes a typed error.

    The readers check their input and raise typed errors themselves; an exception
    that reaches this net is a missing check, reported as :class:`UnexpectedReadError`
    (the fuzzer counts those as untyped).
    """
    try:
        return mod.read(path, **options)
    except VolumenError:
        raise
    except MemoryError as exc:
        raise DataSizeError(path, "ran out of memory reading it (the header asks for more than this machine "
                                  "has)") from exc
    except (PermissionError, IsADirectoryError) as exc:
        raise VolumeReadError(path, f"could not be read ({exc.strerror}: {exc.filename})") from exc
    except (KeyboardInterrupt, SystemExit, GeneratorExit):
        raise
    except BaseException as exc:  # the net; BaseException because Rust decoders panic with pyo3's
        # PanicException, which is not an Exception
        text = str(exc).splitlines()[0][:300] if str(exc) else ""
        raise UnexpectedReadError(path, f"could not be read ({type(exc).__name__}: {text})") from exc


def load(path: str | os.PathLike | Sequence[str | os.PathLike], *, format: str | None = None,
         nonfinite: NonFinitePolicy = "zero", resample: bool = False, allow_outside: bool = False,
         **options) -> Volume:
    """Read a volume from a file, a DICOM folder, or a list of DICOM files.

    Parameters
    ----------
    path : path or list of paths
        A volume file (``.nii``, ``.nii.gz``, ``.nrrd``, ``.nhdr``, ``.mha``, ``.mhd``,
        ``.vtk``, ``.npy``, ``.npz``, ``.raw``), an OME-Zarr / Zarr folder (read lazily;
        ``level=`` picks the pyramid level), a DICOM file, a folder holding one DICOM
        series, or a list of DICOM files.
    format : str, optional
        Force a format (one of ``READ_FORMATS``) instead of detecting it.
    nonfinite : {"zero", "min", "error", "keep"}
        What to do with NaN/inf values in float data: replace them by 0 (default)
        or by the finite minimum, raise :class:`NonFiniteValuesError`, or keep them.
        Replacing or keeping records a line in ``volume.meta["warnings"]``.
    resample : bool
        Make non-uniform slice spacing uniform (DICOM) by resampling onto the
        smallest spacing found. Without it such a series loads as it is, with a
        warning in ``meta["warnings"]`` and the positions in ``meta["slice_positions"]``.
    allow_outside : bool
        Let a header (MetaImage ``ElementDataFile``, NRRD ``data file``) name data files
        outside its own folder. Without it such a file raises :class:`OutsideFolderError`.
    **options
        Passed to the format's reader: ``series=UID`` for DICOM; ``shape``,
        ``dtype``, ``spacing``, ``byte_order``, ``offset`` for raw files; ``key`` for npz.

    Returns
    -------
    Volume
        Data ``[z, y, x]`` in physical units (CT in HU), affine to RAS+ mm.

    Raises
    ------
    VolumeReadError
        Or a subclass, naming the file and the problem.
    """
    if nonfinite not in ("zero", "min", "error", "keep"):
        raise ValueError(f"nonfinite must be one of 'zero', 'min', 'error', 'keep', got {nonfinite!r}")
    if not isinstance(path, (list, tuple)):
        if not Path(path).exists():
            raise MissingPathError(path, "no such file or folder")
    elif len(path) == 0:
        raise MissingPathError(None, "an empty list of DICOM files was given")
    fmt = format or detect_format(path)
    if fmt not in READ_FORMATS:
        raise UnknownFormatError(path, f"unknown format {fmt!r}; choose one of {sorted(READ_FORMATS)}")
    mod = _module(fmt)
    if fmt == "dicom":
        options["resample"] = resample
    if allow_outside and "allow_outside" in inspect.signature(mod.read).parameters:
        options["allow_outside"] = True
    _check_options(mod.read, fmt, path, options)
    vol = _read(mod, path, options)
    vol.meta.setdefault("source", [os.fspath(p) for p in path] if isinstance(path, (list, tuple)) else os.fspath(path))
    vol.meta.setdefault("format", fmt)
    return _apply_nonfinite(vol, nonfinite, path)


def save(volume: Volume, path: str | os.PathLike, *, format: str | None = None, **options) -> None:
    """Write ``volume`` keeping data, spacing and affine.

    The format comes from the suffix (``.nii``, ``.nii.gz``, ``.nrrd``, ``.mha``,
    ``.mhd``, ``.npy``, ``.npz``) or from ``format``. ``options`` go to the writer
    (e.g. ``encoding="gzip"`` for NRRD, ``compress=True`` for MetaImage). Raises
    :class:`VolumeWriteError` for an unknown suffix, a colour volume or a failed write.
    """
    p = Path(path)
    if format is None:
        suf = _suffix(p)
        format = next((n for n in WRITE_FORMATS if suf in READ_FORMATS[n][1]), None)
        if format is None:
            raise VolumeWriteError(p, f"cannot write {suf or '(no suffix)'!r}; volumen writes .nii, .nii.gz, "
                                      ".nrrd, .mha, .mhd, .npy, .npz and .zarr (OME-Zarr)")
    if format not in WRITE_FORMATS:
        raise VolumeWriteError(p, f"cannot write format {format!r}; choose one of {list(WRITE_FORMATS)}")
    if not p.parent.exists():
        raise VolumeWriteError(p, f"folder {p.parent} does not exist")
    if volume.is_color:
        raise VolumeWriteError(p, "is to hold a colour (RGB) volume, which volumen does not write yet; save its grey "
                                  "values instead: volume.with_data(volume.luminance())")
    try:
        _module(format).write(volume, p, **options)
    except VolumeWriteError:
        raise
    except OSError as exc:
        raise VolumeWriteError(p, f"could not write: {exc}") from exc
