"""Numba's on-disk cache, keyed on the whole ray caster's sources rather than on each function's own file.

A kernel here is compiled from pieces in several modules (``_march`` calls
the mode pieces of ``_composite`` / ``_iso`` / ..., the lighting of
``_shade``), and Numba's cache checks only the calling function's file: a
change to a piece would leave the cached kernel stale. The locators below
(registered before any ``@njit(cache=True)`` function of the package is
defined) give every function of ``volumen.render.raycast`` and
``volumen.render.optics`` one source stamp: the modification times and sizes
of all those files, so editing any of them recompiles them all. Packages whose
own kernels call the ray caster's functions (endoscopy's collision march)
add their sources with :func:`stamp_sources` before defining them.
"""

from __future__ import annotations

import os
from pathlib import Path

from numba.core import caching

__all__ = ["install", "installed", "stamp_sources"]

_HERE = Path(__file__).resolve().parent
_FILES = sorted(_HERE.glob("*.py")) + [_HERE.parent / "optics.py"]


def stamp_sources(folder) -> None:
    """Key the cached kernels of every ``.py`` file in ``folder`` on the ray caster's sources and theirs: their
    kernels inline ray-caster functions, which Numba's own check (the calling file only) would not see change."""
    for f in sorted(Path(folder).resolve().glob("*.py")):
        if f not in _FILES:
            _FILES.append(f)


def _ours(py_file) -> bool:
    return Path(py_file).resolve() in _FILES


def _stamp() -> tuple:
    return tuple((f.name, os.stat(f).st_mtime, os.stat(f).st_size) for f in _FILES)


class _Stamped:
    @classmethod
    def from_function(cls, py_func, py_file):
        if not _ours(py_file):
            return None
        return super().from_function(py_func, py_file)

    def get_source_stamp(self):
        return _stamp()


class _UserProvided(_Stamped, caching.UserProvidedCacheLocator):
    pass


class _InTree(_Stamped, caching.InTreeCacheLocator):
    pass


def install() -> None:
    """Put the package's locators first (idempotent)."""
    locators = caching.CacheImpl._locator_classes
    for cls in (_InTree, _UserProvided):
        if cls not in locators:
            locators.insert(0, cls)


install()
#: True once the package's locators are in place (importing this module installs them)
installed = True
