"""Typed errors of volumen.

Every failure to read or write a volume is a :class:`VolumeReadError` (or a
subclass) that names the file and says what is wrong, so the command line and
the application can show one clear line instead of a traceback.
"""

from __future__ import annotations

import difflib
import importlib
import os

__all__ = [
    "VolumenError",
    "MeasurementError",
    "VolumeReadError",
    "MissingPathError",
    "UnknownFormatError",
    "CorruptDataError",
    "DataSizeError",
    "SeriesError",
    "MultipleSeriesError",
    "MissingDependencyError",
    "NonFiniteValuesError",
    "VolumeWriteError",
    "SampleDataMissingError",
    "LumenError",
    "LabelError",
    "UnexpectedReadError",
    "OutsideFolderError",
    "DeviceLimitError",
    "ArchiveError",
    "ArchiveConfigError",
    "ArchiveUnreachableError",
    "ArchiveAuthError",
    "ArchiveRefusedError",
    "ArchiveNotFoundError",
    "RetrieveCancelled",
    "NoDisplayError",
    "UnknownChoiceError",
    "OutsideVolumeError",
    "MissingExtraError",
    "ModalityError",
    "EXTRAS",
    "choice_message",
    "require",
]


class VolumenError(Exception):
    """Base class of every error volumen raises on purpose."""


class VolumeReadError(VolumenError):
    """A volume could not be read.

    Parameters
    ----------
    path : str or os.PathLike or None
        The file or folder that failed.
    problem : str
        What is wrong, in words a user understands.
    """

    def __init__(self, path, problem: str):
        self.path = None if path is None else os.fspath(path)
        self.problem = problem
        where = f"{self.path}: " if self.path is not None else ""
        super().__init__(f"{where}{problem}")


class MissingPathError(VolumeReadError, FileNotFoundError):
    """The path does not exist."""


class UnknownFormatError(VolumeReadError):
    """The file's format is not one volumen reads (or writes)."""


class CorruptDataError(VolumeReadError):
    """The file exists and claims a known format, but its content is broken."""


class DataSizeError(CorruptDataError):
    """The data is shorter or longer than its header (or the caller) says."""


class SeriesError(VolumeReadError):
    """A DICOM series is inconsistent (mixed sizes, orientations, missing pixels...)."""


class MultipleSeriesError(SeriesError):
    """A folder holds several DICOM series and none was chosen.

    ``series`` lists ``(uid, description, n_slices)`` for each one.
    """

    def __init__(self, path, series: list[tuple[str, str, int]]):
        self.series = list(series)
        listed = "; ".join(f"{uid} {desc or '(no description)'}, {n} slice{'' if n == 1 else 's'}"
                           for uid, desc, n in self.series)
        super().__init__(path, f"holds {len(self.series)} DICOM series ({listed}); choose one with --series UID "
                               "(series=UID in Python)")


class MissingDependencyError(VolumeReadError):
    """Reading needs a package that is not installed; the message names it."""


class NonFiniteValuesError(VolumeReadError):
    """The data holds NaN or infinite values and the caller asked for an error."""


class VolumeWriteError(VolumenError):
    """A volume could not be written."""

    def __init__(self, path, problem: str):
        self.path = None if path is None else os.fspath(path)
        self.problem = problem
        super().__init__(f"{self.path}: {problem}")


class SampleDataMissingError(VolumeReadError):
    """Sample data that volumen looks for on the machine is not installed."""


class LumenError(VolumenError, ValueError):
    """No usable lumen: a point outside the scan or in no lumen, two points in lumens that do not
    connect, a lumen mask that does not fit the scan. The message names the point or the file."""


class MeasurementError(VolumenError, ValueError):
    """Measurements that do not belong where they are used: made on another scan than the one loaded, an SR of
    another study, a file that holds none. The message names the file and both scans or studies."""


class UnexpectedReadError(CorruptDataError):
    """A reader met a failure no check anticipated (the load path's last-resort net).

    The message names the file and the original exception; ``__cause__`` holds it.
    The fuzzer counts these as untyped: each one is a missing check to add.
    """


class OutsideFolderError(VolumeReadError):
    """A header names a data file outside its own folder and the caller did not allow it
    (``volumen.load(..., allow_outside=True)``)."""


class DeviceLimitError(VolumenError, ValueError):
    """A device cannot hold what a picture needs (a volume past the OpenGL 3-D texture size...). The message
    names the limit, the size asked for, and the device to use instead."""


class LabelError(VolumeReadError, ValueError):
    """A segmentation that cannot be used: a names table that does not match its label map, labels whose grid
    does not overlap the scan, a DICOM SEG that segments another series. The message names the file."""


class ArchiveError(VolumenError):
    """A PACS or research archive (DICOMweb, DIMSE) failed; the message names the server, never a password.

    Parameters
    ----------
    server : str or None
        How the server is named to the user (``archive (http://host:8042/dicom-web)``).
    problem : str
        What went wrong, in one line.
    """

    def __init__(self, server: str | None, problem: str):
        self.server = server
        self.problem = problem
        super().__init__(f"server {server}: {problem}" if server else problem)


class ArchiveConfigError(ArchiveError, ValueError):
    """The server configuration (``servers.toml``, a server given on the command line) is unusable: an unknown
    name, a bad key, a password in a file others can read, a password given on the command line."""


class ArchiveUnreachableError(ArchiveError, ConnectionError):
    """The server did not answer, or stopped answering in the middle of a transfer (what was fetched is kept
    and a rerun resumes)."""


class ArchiveAuthError(ArchiveError, PermissionError):
    """The server refused the credentials (HTTP 401 / 403)."""


class ArchiveRefusedError(ArchiveError):
    """The server refused or aborted the request: a rejected DIMSE association, a failed C-FIND / C-GET /
    C-MOVE / C-STORE, an HTTP error other than authentication."""


class ArchiveNotFoundError(ArchiveError, LookupError):
    """The study, series or instance asked for is not on the server (deleted since it was found?)."""


class RetrieveCancelled(ArchiveError):
    """The user cancelled a retrieve; what was fetched is kept (under a temporary name) for a later rerun."""


class NoDisplayError(VolumenError, RuntimeError):
    """The desktop application cannot open a window here: no display, or Qt's system libraries are missing. The
    message says which and what to do (``volumen view --screenshot`` needs no display)."""



def choice_message(what: str, value, valid) -> str:
    """One line: ``what`` ``value`` is not one of the ``valid`` values, with the closest one when a value is close
    (``preset 'ct-vessel' is not one of ct-bone, ct-vessels, ...; did you mean 'ct-vessels'?``)."""
    names = [str(v) for v in valid]
    text = str(value).lower()
    starts = [n for n in names if text and n.lower().startswith(text)]  # a name cut short: 'soft' -> soft-tissue
    close = starts if len(starts) == 1 else difflib.get_close_matches(text, names, n=1, cutoff=0.6)
    hint = f"; did you mean {close[0]!r}?" if close else ""
    return f"{what} {value!r} is not one of {', '.join(names)}{hint}"


class UnknownChoiceError(VolumenError, ValueError):
    """A name that is not one of the valid ones (a preset, a view, a window...); the message lists them and the
    closest one (:func:`choice_message`)."""

    def __init__(self, what: str, value, valid):
        self.value, self.valid = value, tuple(valid)
        super().__init__(choice_message(what, value, self.valid))


class OutsideVolumeError(VolumenError, IndexError):
    """A point or slice outside the volume; the message gives the point in world mm, the volume's extent and its
    file."""


class ModalityError(VolumenError, ValueError):
    """A setting made for one modality asked of a scan of another (a CT window in HU on an MRI); the message
    says what to give instead."""


#: the optional packages volumen imports and the extra of ``pip install 'volumen[EXTRA]'`` that brings each
#: (pyproject.toml, [project.optional-dependencies])
EXTRAS: dict[str, str] = {
    "PySide6": "gui", "shiboken6": "gui", "moderngl": "gl", "distributed": "scale", "dask": "scale",
    "zarr": "scale", "ipywidgets": "notebook", "jupyter_rfb": "notebook", "simplejpeg": "notebook",
    "imageio_ffmpeg": "video", "numba_cuda": "cuda", "vtk": "bench", "matplotlib": "report",
}


class MissingExtraError(VolumenError, ImportError):
    """An optional package is not installed; the message names the extra that installs it
    (``pip install 'volumen[gui]'``).

    Parameters
    ----------
    module : str
        The package's import name (``PySide6``, ``moderngl``...).
    purpose : str, optional
        What needed it, in words (``the desktop application``).
    """

    def __init__(self, module: str, purpose: str | None = None):
        self.module = module.split(".")[0]
        self.extra = EXTRAS.get(self.module)
        need = f"{purpose} needs {self.module}" if purpose else f"{self.module} is not installed"
        hint = f"pip install 'volumen[{self.extra}]'" if self.extra else f"pip install {self.module}"
        super().__init__(f"{need}: {hint}")


def require(module: str, purpose: str | None = None):
    """Import ``module``; :class:`MissingExtraError` naming its extra when it (or a package it needs) is missing."""
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        missing = (exc.name or module).split(".")[0]
        raise MissingExtraError(missing if missing in EXTRAS else module, purpose) from None
