"""The error contract of every sub-command: a failure is one line on stderr naming the command and what went wrong,
exit status 1 (3 only for a failure nobody anticipated), and the outputs it would have written are not left behind
half made (a folder it created, a file it began)."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

__all__ = ["explain", "OutputFiles", "FAILED", "INTERNAL"]

#: exit status of an error volumen anticipated (a bad file, option, point, a missing optional package)
FAILED = 1
#: exit status of a failure nobody anticipated (a bug: ``VOLUMEN_DEBUG=1`` shows the traceback)
INTERNAL = 3


def explain(exc: BaseException) -> tuple[int, str]:
    """``(exit status, one line)`` for an exception a command raised: ``error: ...`` with :data:`FAILED`, or
    ``internal error: ...`` with :data:`INTERNAL` for the unexpected."""
    code, line = _classify(exc)
    return code, (f"error: {line}" if code == FAILED else f"internal error: {line}")


def _classify(exc: BaseException) -> tuple[int, str]:
    from volumen.errors import EXTRAS, MissingExtraError, VolumenError

    if isinstance(exc, VolumenError):
        return FAILED, str(exc)
    if isinstance(exc, ImportError) and (exc.name or "").split(".")[0] in EXTRAS:
        return FAILED, str(MissingExtraError(exc.name))
    if isinstance(exc, (ValueError, IndexError)) or _gl_unavailable(exc):
        return FAILED, str(exc)
    if isinstance(exc, OSError):  # a file or folder the command reads or writes
        where = f"{exc.filename}: " if getattr(exc, "filename", None) else ""
        return FAILED, f"{where}{exc.strerror or exc}"
    return INTERNAL, f"{type(exc).__name__}: {exc} (set VOLUMEN_DEBUG=1 for the traceback)"


def _gl_unavailable(exc: BaseException) -> bool:
    """Whether ``exc`` says no OpenGL context can be made here (a fact of the machine, not a bug)."""
    if type(exc).__name__ != "RasterUnavailable":
        return False
    from volumen.render.raster import RasterUnavailable

    return isinstance(exc, RasterUnavailable)


class OutputFiles:
    """The paths a command was asked to write (its ``OUTPUTS`` arguments) that did not exist before it ran;
    :meth:`discard` removes what of them a failed run left (from the first folder it created on the way).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line.
    names : sequence of str
        The argument names that hold output paths (``out``, ``save_settings``...).
    """

    def __init__(self, args, names=()):
        self.new: list[Path] = []
        for name in names:
            value = getattr(args, name, None)
            if value and "://" not in str(value):
                top = _first_missing(Path(value))
                if top is not None:
                    self.new.append(top)

    def discard(self) -> None:
        """Remove each output path, or the folder created on the way to it, that exists now but did not before."""
        for path in self.new:
            if path.is_dir() and not path.is_symlink():
                shutil.rmtree(path, ignore_errors=True)
            elif path.exists() or path.is_symlink():
                os.unlink(path)


def _first_missing(path: Path) -> Path | None:
    """The outermost of ``path`` and its parents that does not exist (None when ``path`` exists)."""
    path = path.absolute()
    if path.exists() or path.is_symlink():
        return None
    while not path.parent.exists() and path.parent != path:
        path = path.parent
    return path
