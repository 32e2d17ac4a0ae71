"""One writer at a time per Numba cache index, across processes, the data before the index, and an index that
cannot be read back taken for stale.

Numba's disk cache keeps one index file per cached function (signature -> data file), which
``numba.core.caching.IndexDataCacheFile.save`` reads, extends and writes back, and then writes the data file.
Two processes that compile two signatures of one function at the same time -- the warming processes of
:func:`volumen.render.warm`, the app's background compile beside its drawing, the suite's two workers -- can
both read the old index and both pick the same data file name. Then one kernel is lost from the index (two such
writers of 200 entries each kept 228-329 of the 400), or the index names one signature's entry while the file
holds the other's machine code, which a later process would load and call with the wrong arguments. And since
the index is written first, a reader between the two writes (or after a process killed between them) could
load a stale data file of that name left from before the sources changed: the numbering restarts at 1 then.

:func:`install` replaces ``save`` with the same steps under an inter-process lock (``flock``) on
``<index>.lock`` beside the index (in the temporary folder where that cannot be made): read the index, pick
the name, write the data file, then the index. Loading takes no lock: files are replaced whole (Numba writes a
temporary file and renames it). Where no lock can be taken at all, it saves as Numba does.

An index is one pickle of ``(source stamp, {signature: data file})``, and Numba unpickles the whole of it before
it compares the stamp. An index written by older sources can name a type that the new sources renamed or
removed (the signature of ``_trace_tiles`` names the mode tag of each kernel, and mip's tag ``Mip`` became
``Projection``): unpickling it raised ``AttributeError`` and every drawing command failed with an internal error
until the user deleted the cache. :func:`install` also replaces ``_load_index`` so that an index it cannot
unpickle reads as empty, which is what Numba answers for a stale stamp: the kernel compiles, and saving it
writes a fresh index over the old one. A file it cannot open still raises, as in Numba.

Like the cache stamp (:mod:`._stamp`) it is about correctness, so it does not stand down outside the tested
Numba range; it steps aside where Numba's class lacks the helpers it calls. Upstream: the same race, met by
concurrent processes, is numba/numba#10128 (open), where Numba's developers proposed a file lock; this goes
when Numba takes one.
"""

from __future__ import annotations

import contextlib
import hashlib
import itertools
import os
import pickle
import tempfile
from pathlib import Path

__all__ = ["install", "installed", "lock_path", "UNREADABLE"]

_state = {"installed": False}
#: what ``save`` calls on Numba's class
_HELPERS = ("_load_index", "_save_index", "_save_data", "_data_name", "_index_path")
#: what unpickling an index of older sources raises: a name or module gone, a pickle cut short or foreign
UNREADABLE = (AttributeError, ImportError, EOFError, IndexError, KeyError, TypeError, ValueError,
              pickle.UnpicklingError)


def lock_path(index_path, beside: bool = True) -> Path:
    """The lock file of one cache index: ``<index>.lock`` beside it, or (``beside`` False) one named after its
    path in the temporary folder."""
    if beside:
        return Path(f"{index_path}.lock")
    d = Path(tempfile.gettempdir()) / f"volumen-numba-index-locks-{os.getuid()}"
    d.mkdir(exist_ok=True)
    return d / (hashlib.sha1(os.fsencode(os.path.abspath(index_path))).hexdigest() + ".lock")


@contextlib.contextmanager
def _locked(index_path):
    """Hold the index's lock (nothing where no lock file can be opened)."""
    import fcntl

    fd = None
    for beside in (True, False):
        try:  # readable by every user of a shared kernel folder (the umask decides), read-only where another made it
            path = lock_path(index_path, beside)
            try:
                fd = os.open(path, os.O_CREAT | os.O_RDWR, 0o666)
            except PermissionError:
                fd = os.open(path, os.O_RDONLY)
            break
        except OSError:
            continue
    if fd is None:
        yield
        return
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        fcntl.flock(fd, fcntl.LOCK_UN)  # explicitly: a child forked meanwhile shares the descriptor
        os.close(fd)


def _save(self, key, data):
    """Numba's ``save`` under the index's lock, writing the data file before the index names it."""
    with _locked(self._index_path):
        overloads = self._load_index()
        name = overloads.get(key)
        if name is None:
            existing = set(overloads.values())
            name = next(n for n in (self._data_name(i) for i in itertools.count(1)) if n not in existing)
        self._save_data(name, data)
        if overloads.get(key) != name:
            overloads[key] = name
            self._save_index(overloads)


def _load_index(self):
    """Numba's ``_load_index``, where an index that cannot be unpickled reads as empty (stale)."""
    try:
        return _load_index.__wrapped__(self)
    except UNREADABLE:
        return {}


def install() -> bool:
    """Replace ``IndexDataCacheFile.save`` and ``_load_index`` once (process-wide); whether they are replaced."""
    if _state["installed"]:
        return True
    try:
        import fcntl  # noqa: F401 - POSIX only
    except ImportError:
        return False
    from numba.core import caching

    cls = getattr(caching, "IndexDataCacheFile", None)
    if cls is None or not all(hasattr(cls, h) for h in _HELPERS[:-1]) or \
            _HELPERS[-1] not in cls.__init__.__code__.co_names:
        return False
    _save.__wrapped__ = cls.save
    _load_index.__wrapped__ = cls._load_index
    cls.save = _save
    cls._load_index = _load_index
    _state["installed"] = True
    return True


def installed() -> bool:
    """Whether ``save`` and ``_load_index`` are replaced in this process."""
    return _state["installed"]
