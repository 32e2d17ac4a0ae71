"""One writer at a time per Numba cache index, across processes.

Numba's disk cache keeps one index file per cached function (signature -> data file), which
``numba.core.caching.IndexDataCacheFile.save`` reads, extends and writes back. Two processes that compile two
signatures of one function at the same time -- the warming processes of :func:`volumen.render.warm`, the app's
background compile beside its drawing, the suite's two workers -- can both read the old index and both pick the
same data file name. Then one kernel is lost from the index, or, worse, the index names one signature's entry
and the file holds the other's machine code, which a later process would load and call with the wrong
arguments. :func:`install` wraps ``save`` in an inter-process lock (``flock``) named after the index's path, so
each save reads the index the last one wrote. Loading takes no lock: files are replaced whole (Numba writes a
temporary file and renames it), and an entry whose data file is not written yet reads as a miss.

Like the cache stamp (:mod:`._stamp`) it is about correctness, so it does not stand down outside the tested
Numba range; it steps aside where Numba's class has no ``save`` or ``_index_path``. Upstream: the same race,
met by concurrent processes, is numba/numba#10128 (open), where Numba's developers proposed a file lock; this
goes when Numba takes one.
"""

from __future__ import annotations

import hashlib
import os
import tempfile
from pathlib import Path

__all__ = ["install", "installed", "lock_path"]

_state = {"installed": False}


def lock_path(index_path) -> Path:
    """The lock file of one cache index: in the temporary folder (the cache folder may be shared or read-only)."""
    d = Path(tempfile.gettempdir()) / f"volumen-numba-index-locks-{os.getuid()}"
    d.mkdir(exist_ok=True)
    return d / (hashlib.sha1(os.fsencode(os.path.abspath(index_path))).hexdigest() + ".lock")


def _locked(original):
    import fcntl

    def save(self, key, data):
        fd = os.open(lock_path(self._index_path), os.O_CREAT | os.O_RDWR, 0o600)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX)
            return original(self, key, data)
        finally:
            os.close(fd)  # closing the only descriptor releases the lock

    save.__wrapped__ = original
    return save


def install() -> bool:
    """Wrap ``IndexDataCacheFile.save`` once (process-wide); whether it is wrapped."""
    if _state["installed"]:
        return True
    try:
        import fcntl  # noqa: F401 - POSIX only
    except ImportError:
        return False
    from numba.core import caching

    cls = getattr(caching, "IndexDataCacheFile", None)
    if cls is None or not hasattr(cls, "save") or "_index_path" not in cls.__init__.__code__.co_names:
        return False
    cls.save = _locked(cls.save)
    _state["installed"] = True
    return True


def installed() -> bool:
    """Whether ``save`` is wrapped in this process."""
    return _state["installed"]
