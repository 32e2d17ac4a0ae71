"""The fuzz worker: a long-lived process that loads mutants one by one and reports how each went.

Protocol: one JSON task per line on stdin ``{"path", "folder", "options"}``; one JSON
result per line on the protocol pipe (the original stdout; the readers' own prints go
to /dev/null) ``{"outcome", "detail"}``. The address space is limited with
``RLIMIT_AS`` after the readers are imported, and an audit hook records every file
opened while a mutant loads: a file outside the mutant's folder (and outside Python's
own installation) makes the outcome ``outside-path`` whatever the load returned.

Outcomes decided here: ``ok``, ``typed`` (a :class:`~volumen.errors.VolumeReadError`
naming the file), ``untyped`` (any other exception, a typed error without the file, or
one raised by the load path's last-resort net), ``out-of-memory`` (``MemoryError``,
also when wrapped in a typed error) and ``outside-path``. The campaign adds ``hang``
and ``crash`` from outside.
"""

from __future__ import annotations

import json
import os
import resource
import sys

__all__ = ["main"]

_READERS = ("_dicom", "_dicom_series", "_metaimage", "_nifti", "_nrrd", "_numpy", "_raw", "_vtk")
_opened: list[str] | None = None


def _audit(event: str, args) -> None:
    if _opened is not None and event == "open" and args and isinstance(args[0], (str, bytes, os.PathLike)):
        _opened.append(os.fsdecode(args[0]))


def _allowed_roots() -> tuple[str, ...]:
    roots = {sys.prefix, sys.base_prefix, sys.exec_prefix, "/proc", "/dev", "/sys"}
    roots.update(p for p in sys.path if p and os.path.isdir(p))
    return tuple(os.path.realpath(r) for r in roots)


def _outside(folder: str, roots: tuple[str, ...]) -> str | None:
    base = os.path.realpath(folder)
    campaign = os.path.dirname(base)  # the canary's parent: never an allowed root
    for name in _opened or ():
        real = os.path.realpath(name if os.path.isabs(name) else os.path.join(os.getcwd(), name))
        if real == base or real.startswith(base + os.sep):
            continue
        if real.startswith(campaign + os.sep):
            return real
        if not any(real == r or real.startswith(r + os.sep) for r in roots):
            return real
    return None


def _chain(exc: BaseException):
    seen = set()
    while exc is not None and id(exc) not in seen:
        seen.add(id(exc))
        yield exc
        exc = exc.__cause__ or exc.__context__


def classify(exc: BaseException) -> tuple[str, str]:
    """The outcome of an exception raised by ``volumen.load`` and a one-line detail."""
    from volumen.errors import UnexpectedReadError, VolumeReadError

    detail = f"{type(exc).__name__}: {exc}".splitlines()[0][:300] if str(exc) else type(exc).__name__
    if any(isinstance(e, MemoryError) for e in _chain(exc)):
        return "out-of-memory", detail
    if isinstance(exc, UnexpectedReadError):
        cause = exc.__cause__
        return "untyped", f"net: {type(cause).__name__}: {str(cause)[:200]}" if cause else detail
    if isinstance(exc, VolumeReadError):
        return ("typed", detail) if exc.path else ("untyped", "typed error without the file: " + detail)
    return "untyped", detail


def _run(task: dict, roots: tuple[str, ...]) -> dict:
    global _opened
    from volumen.io import load

    _opened = []
    try:
        load(os.path.join(task["folder"], task["path"]), **task.get("options", {}))
        outcome, detail = "ok", ""
    except RecursionError as exc:  # before BaseException handling: the stack is unwound by now
        outcome, detail = "untyped", f"RecursionError: {str(exc)[:200]}"
    except (KeyboardInterrupt, SystemExit):
        raise
    except BaseException as exc:  # noqa: BLE001  (classifying every exception is the point)
        outcome, detail = classify(exc)
    finally:
        where = _outside(task["folder"], roots)
        _opened = None
    if where is not None:
        outcome, detail = "outside-path", f"opened {where} ({outcome}: {detail[:150]})"
    return {"outcome": outcome, "detail": detail}


def main() -> None:
    import importlib

    for name in _READERS:
        importlib.import_module(f"volumen.io.{name}")
    for name in ("nibabel", "nrrd", "pydicom", "SimpleITK", "zipfile", "gzip", "bz2", "numpy.lib.format"):
        try:
            importlib.import_module(name)
        except ImportError:
            pass
    proto = os.fdopen(os.dup(1), "w", buffering=1)
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)
    limit = int(os.environ.get("VOLUMEN_FUZZ_MEMORY", str(4 << 30)))
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    roots = _allowed_roots()
    sys.addaudithook(_audit)
    for line in sys.stdin:
        task = json.loads(line)
        try:
            result = _run(task, roots)
        except MemoryError:
            result = {"outcome": "out-of-memory", "detail": "MemoryError outside the load call"}
        proto.write(json.dumps(result) + "\n")


if __name__ == "__main__":
    main()
