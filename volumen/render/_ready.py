"""Which CPU ray-casting kernels this process can draw without compiling them (``volumen.render._standin`` asks).

A kernel (``_warm.kernel_key``) is ready when this process drew it on the CPU (``render`` says so), when a child
of ``warm`` put it in Numba's disk cache, or when a marker says an earlier process did either: each kernel noted
ready leaves an empty file beside Numba's cache (``NUMBA_CACHE_DIR``, else the ray caster's ``__pycache__``, else,
where that is not writable, the user's cache folder, where Numba then caches too),
named by a hash of its key, the ray caster's source stamp (``volumen.jit.source_stamp``, what Numba's cache is
keyed on), the Numba release and the host CPU. So a new session with a filled cache draws its first picture on
the CPU at once, as it did before stand-ins. A marker of another build or machine does not match. A marker whose
cache entry was deleted (or a cache that could not be written) costs only what a first picture cost without
stand-ins: the CPU compiles the kernel while the viewer waits. Where no marker can be written, none is.
"""

from __future__ import annotations

import hashlib
import os
import threading
from pathlib import Path

__all__ = ["note_ready", "is_ready", "marker_dir", "when_ready"]

_READY: set = set()
_LOCK = threading.Lock()
#: callables(key) told of each kernel noted ready in this process (``_standin`` ends a stand-in with them)
_HOOKS: list = []


def when_ready(hook) -> None:
    """Call ``hook(key)`` for each kernel :func:`note_ready` records from now on in this process."""
    with _LOCK:
        _HOOKS.append(hook)


def _writable(folder: Path) -> bool:
    """Whether ``folder`` (or, while it does not exist, the folder it would be made in) can be written to."""
    return os.access(folder if folder.exists() else folder.parent, os.W_OK)


def marker_dir() -> Path:
    """The folder of the markers, beside Numba's cache: in ``NUMBA_CACHE_DIR`` when set, else in the ray caster's
    ``__pycache__``, else (an install the user cannot write to) in the user's cache folder, as Numba's locators
    pick (``volumen.jit._stamp``)."""
    root = os.environ.get("NUMBA_CACHE_DIR")
    if root:
        return Path(root) / "volumen-kernels"
    tree = Path(__file__).resolve().parent / "raycast" / "__pycache__"
    if _writable(tree):
        return tree / "volumen-kernels"
    from numba.misc.appdirs import AppDirs

    return Path(AppDirs(appname="numba", appauthor=False).user_cache_dir) / "volumen-kernels"


def _marker(key: tuple) -> Path:
    from llvmlite import binding
    from numba import __version__

    from ..jit import source_stamp
    from ._kernel_sources import SOURCES

    text = repr((key, source_stamp(SOURCES), __version__, binding.get_host_cpu_name()))
    return marker_dir() / hashlib.sha256(text.encode()).hexdigest()[:32]


def note_ready(key: tuple) -> None:
    """Record that the kernel of ``key`` is compiled and in Numba's disk cache (here, and by a marker)."""
    with _LOCK:
        if key in _READY:
            return
        _READY.add(key)
        hooks = tuple(_HOOKS)
    for hook in hooks:
        hook(key)
    try:
        marker = _marker(key)
        marker.parent.mkdir(parents=True, exist_ok=True)
        marker.touch()
    except OSError:
        pass  # no folder to write to: later sessions show a stand-in first


def is_ready(key: tuple) -> bool:
    """Whether the kernel of ``key`` draws without compiling: noted in this process, or marked by an earlier one."""
    with _LOCK:
        if key in _READY:
            return True
    try:
        found = _marker(key).is_file()
    except OSError:
        found = False
    if found:
        with _LOCK:
            _READY.add(key)
    return found
