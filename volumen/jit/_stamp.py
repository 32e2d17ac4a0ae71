"""Numba's on-disk cache keyed on every source a kernel is compiled from, not only its own file.

A cached kernel inlines (or links) functions of other files: the ray caster's skeleton calls the mode pieces
of ``_composite`` / ``_iso`` / ..., the lighting of ``_shade`` and the thread counter of
:mod:`volumen.jit._threads`; endoscopy's collision march calls the ray caster's sampling; marching cubes
calls ``_mc_rows``' word helpers and freezes the tables of ``_mc_tables`` into its code. Numba checks only
the calling function's own file, so a change to one of those would leave the cached kernel stale. A package
registers its kernels' files with :func:`stamp_sources` *before defining them* (its ``__init__`` does it
first); the cache locators below then give each registered file the stamp of its whole group: the
modification times and sizes of every file in it, so editing any of them recompiles the group.

This puts three locators at the front of ``numba.core.caching.CacheImpl._locator_classes`` (a private list,
the fourth patch of Numba's internals, guarded by :mod:`._guard`; upstream: numba/numba#1833, "Caching
issue: functions in different modules", open; it goes when Numba's cache keys a kernel on the files of the
functions it calls, which numba/numba#8396 is hoped to do). Unlike the inliner's patches it does not stand down
outside the tested Numba range, because without it a cache could be stale (wrong); it steps aside only when
Numba lacks the list or the locator methods it extends, and then says so once. The three are Numba's own
``NUMBA_CACHE_DIR``, ``__pycache__`` beside the sources and, where that folder is not writable (an install a user
cannot write to), the user's cache folder: without the third, such an install kept its kernels keyed on their
own file only.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Iterable
from pathlib import Path

__all__ = ["stamp_sources", "stamped_with", "source_stamp", "install", "installed"]

_PACKAGE = Path(__file__).resolve().parents[1]  # volumen/
#: registered file -> the files its kernels' cache is keyed on (sorted)
_KEYS: dict[Path, tuple[Path, ...]] = {}
_state = {"installed": False}


def stamp_sources(files: Iterable, *, also: Iterable = ()) -> tuple[Path, ...]:
    """Key the cached kernels of each of ``files`` on all of ``files``, ``also`` and the groups ``also`` belong to.

    Parameters
    ----------
    files : iterable of path
        Source files whose ``@njit(cache=True)`` kernels are keyed (call before those kernels are defined).
    also : iterable of path
        More sources they are compiled from; a file registered before brings its whole group.

    Returns
    -------
    tuple of Path
        The group: every file whose stamp the kernels of ``files`` carry.
    """
    own = {Path(f).resolve() for f in files}
    extra = {Path(f).resolve() for f in also}
    group = set(own) | extra
    for f in extra:
        group.update(_KEYS.get(f, ()))
    key = tuple(sorted(group))
    for f in own:
        _KEYS[f] = tuple(sorted(set(_KEYS.get(f, ())) | group))
    install()
    return key


def stamped_with(path) -> tuple[Path, ...]:
    """The files whose stamp the cached kernels of ``path`` carry (empty: not registered, Numba's own check)."""
    return _KEYS.get(Path(path).resolve(), ())


def source_stamp(files: tuple[Path, ...]) -> tuple:
    """The stamp cached kernels keyed on ``files`` carry: each file's name, modification time and size."""
    out = []
    for f in files:
        st = os.stat(f)
        out.append((f.relative_to(_PACKAGE).as_posix() if f.is_relative_to(_PACKAGE) else f.name, st.st_mtime,
                    st.st_size))
    return tuple(out)


def _bases(caching) -> tuple:
    """Numba's user-provided (``NUMBA_CACHE_DIR``), in-tree and user-wide locators (underscored names in older
    releases)."""
    return tuple(getattr(caching, name, None) or getattr(caching, "_" + name, None)
                 for name in ("UserProvidedCacheLocator", "InTreeCacheLocator", "UserWideCacheLocator"))


def _locators():
    from numba.core import caching

    class _Stamped:
        @classmethod
        def from_function(cls, py_func, py_file):
            key = _KEYS.get(Path(py_file).resolve())
            if not key:
                return None
            locator = super().from_function(py_func, py_file)
            if locator is not None:
                locator._volumen_key = key
            return locator

        def get_source_stamp(self):
            return source_stamp(self._volumen_key)

    user_provided, in_tree, user_wide = _bases(caching)

    class _UserProvided(_Stamped, user_provided):
        pass

    class _InTree(_Stamped, in_tree):
        pass

    class _UserWide(_Stamped, user_wide):
        pass

    # Numba's order: NUMBA_CACHE_DIR when set, else beside the sources, else (a read-only install) the user's cache
    return _UserProvided, _InTree, _UserWide


def install() -> bool:
    """Put the stamped locators first in Numba's list (once); whether they are in place."""
    if _state["installed"]:
        return True
    from numba.core import caching

    locators = getattr(getattr(caching, "CacheImpl", None), "_locator_classes", None)
    bases = _bases(caching)
    if not isinstance(locators, list) or not all(hasattr(b, "from_function") and hasattr(b, "get_source_stamp")
                                                 for b in bases):
        warnings.warn("this Numba has no cache locator list volumen can extend: cached kernels are keyed on their "
                      "own file only; after editing volumen's kernels, delete its __pycache__ folders", stacklevel=2)
        return False
    for cls in reversed(_locators()):
        locators.insert(0, cls)
    _state["installed"] = True
    return True


def installed() -> bool:
    """Whether the stamped locators are in place in this process."""
    return _state["installed"]
