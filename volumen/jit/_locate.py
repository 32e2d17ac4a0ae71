"""Compiled kernels kept once per machine, in a folder per content key that every checkout shares.

Numba's disk cache keeps a function's kernels in a folder its locators pick (``__pycache__`` beside the source,
by default) under an index stamped with that one file's contents. :func:`install` puts two locators of volumen's
at the front of ``numba.core.caching.CacheImpl._locator_classes`` (a private list, patched like the inliner and
guarded by ``tests/render/test_inlining.py``'s shape check; upstream: numba/numba#1833, "Caching issue: functions
in different modules", open; it goes when Numba's cache keys a kernel on the files of the functions it calls).
For a file registered with :func:`volumen.jit.stamp_sources`:

* :class:`_Shared` keeps its kernels in :func:`kernel_folder` ``/<key>/<package folder>``, ``<key>`` being the
  first 24 hex digits of its group's content key (:func:`volumen.jit.source_stamp`). A fresh clone, a
  reinstall, a CI run or a second checkout of the same code on the same machine finds the folder the first one
  filled; a change to one source makes a new key for the groups holding that file only, so only their kernels
  compile again; another CPU, Numba or llvmlite has another key. The index's stamp is the key itself.
* :class:`_InTree`, where that folder cannot be written: Numba's ``__pycache__`` beside the source, the index
  stamped with the group's content key (never with the file's own contents alone); where that cannot be written
  either, :class:`_Temporary`: a temporary folder of the process's own (the kernels compile in every process).

Processes that fill one folder at the same time (the suite's workers, ``volumen warm``'s children) write each
index under a lock (:mod:`._savelock`), data files whole (Numba renames a finished temporary file). Each process
touches a key's folder the first time it uses it; a folder not used for :data:`KEEP_DAYS` days is removed when a
new key's folder is made, so old versions of the code do not pile up.
"""

from __future__ import annotations

import os
import re
import shutil
import tempfile
import time
import warnings
from pathlib import Path

from ._stamp import _PACKAGE, source_stamp, stamped_with

__all__ = ["install", "installed", "kernel_folder", "group_folder", "KEEP_DAYS"]

#: a key's folder unused for this many days is removed when another key's folder is made
KEEP_DAYS = 30
#: characters of the content key that name its folder (96 bits)
_KEY_CHARS = 24
_KEY_NAME = re.compile(f"[0-9a-f]{{{_KEY_CHARS}}}")
_state: dict = {"installed": False, "root": None, "touched": set(), "keys": {}}


def _group_key(group: tuple) -> str:
    """The content key of ``group``, worked out once per process: the kernels a process defines are compiled from
    the sources it imported, so the key of those is the one to keep them under (hashing the files again for each
    of the ray caster's two hundred kernels took 1.6 s of a command's start)."""
    key = _state["keys"].get(group)
    if key is None:
        key = _state["keys"][group] = source_stamp(group)
    return key


def kernel_folder(*, refresh: bool = False) -> Path:
    """The root of the kernel folders (``volumen.places.kernel_dir``: ``NUMBA_CACHE_DIR/volumen``, else
    ``VOLUMEN_CACHE_DIR/kernels``, else ``~/.cache/volumen/kernels``). Read once per process, when the first
    kernel is defined (or ``refresh``): a variable changed later (a test's temporary cache folder for archives)
    does not move the kernels of a running process."""
    if _state["root"] is None or refresh:
        from numba.core import config

        from ..places import kernel_dir

        _state["root"] = kernel_dir(config.CACHE_DIR)
    return _state["root"]


def _prune(root: Path, keep: Path) -> None:
    """Remove the key folders under ``root`` other than ``keep`` that no process used for :data:`KEEP_DAYS` days
    (only folders named as keys are: ``VOLUMEN_KERNEL_DIR`` may name a folder that holds other things)."""
    cutoff = time.time() - KEEP_DAYS * 86400
    for folder in root.iterdir() if root.is_dir() else ():
        try:
            if folder != keep and _KEY_NAME.fullmatch(folder.name) and folder.is_dir() and \
                    folder.stat().st_mtime < cutoff:
                shutil.rmtree(folder, ignore_errors=True)
        except OSError:
            continue


def group_folder(files) -> Path:
    """The folder of the kernels compiled from ``files`` (a group): :func:`kernel_folder` ``/<key>``; made and
    marked used (its modification time) the first time a process asks."""
    folder = kernel_folder() / _group_key(tuple(files))[:_KEY_CHARS]
    if folder not in _state["touched"]:
        _state["touched"].add(folder)
        made = not folder.is_dir()
        folder.mkdir(parents=True, exist_ok=True)
        os.utime(folder)
        if made:
            _prune(folder.parent, folder)
    return folder


def _locators():
    from numba.core import caching

    class _Shared(caching._CacheLocator):
        """The group's folder in the machine's kernel cache, the index stamped with the group's content key."""

        def __init__(self, py_func, py_file, group):
            self._py_file = py_file
            self._lineno = py_func.__code__.co_firstlineno
            folder = Path(py_file).resolve().parent
            inside = folder.relative_to(_PACKAGE).as_posix() if folder.is_relative_to(_PACKAGE) else folder.name
            self._stamp = _group_key(group)
            self._path = group_folder(group) / (inside if inside != "." else "volumen")

        def get_cache_path(self):
            return str(self._path)

        def get_source_stamp(self):
            return self._stamp

        def get_disambiguator(self):
            return str(self._lineno)

        @classmethod
        def from_function(cls, py_func, py_file):
            group = stamped_with(py_file)
            if not group:
                return None
            try:
                self = cls(py_func, py_file, group)
                self.ensure_cache_path()
            except (OSError, RuntimeError, KeyError):  # not writable, or no home folder: beside the sources
                return None
            return self

    class _Keyed:
        """One of Numba's locators, for a registered file only, the index stamped with the group's content key."""

        @classmethod
        def from_function(cls, py_func, py_file):
            group = stamped_with(py_file)
            if not group:
                return None
            locator = super().from_function(py_func, py_file)
            if locator is not None:
                locator._volumen_key = _group_key(group)
            return locator

        def get_source_stamp(self):
            return self._volumen_key

    class _InTree(_Keyed, caching.InTreeCacheLocator):
        """Numba's ``__pycache__`` beside the source."""

    class _Temporary(_Keyed, caching.InTreeCacheLocator):
        """A temporary folder of this process's, removed when it ends: where neither the kernel cache nor
        ``__pycache__`` can be written, a registered file's kernels compile in every process rather than fall to
        Numba's own locators, which would key them on their own file only."""

        def __init__(self, py_func, py_file):
            super().__init__(py_func, py_file)
            if _state.get("temporary") is None:
                _state["temporary"] = tempfile.TemporaryDirectory(prefix="volumen-kernels-")
            self._cache_path = _state["temporary"].name

    return _Shared, _InTree, _Temporary


def install() -> bool:
    """Put the content-keyed locators first in Numba's list (once); whether they are in place."""
    if _state["installed"]:
        return True
    from numba.core import caching

    locators = getattr(getattr(caching, "CacheImpl", None), "_locator_classes", None)
    base = getattr(caching, "InTreeCacheLocator", None)
    if not isinstance(locators, list) or not hasattr(caching, "_CacheLocator") or \
            not all(hasattr(base, m) for m in ("from_function", "get_source_stamp", "ensure_cache_path")):
        warnings.warn("this Numba has no cache locator list volumen can extend: cached kernels are keyed on their "
                      "own file only; after editing volumen's kernels, delete its __pycache__ folders", stacklevel=2)
        return False
    for cls in reversed(_locators()):
        locators.insert(0, cls)
    _state["installed"] = True
    return True


def installed() -> bool:
    """Whether the content-keyed locators are in place in this process."""
    return _state["installed"]
