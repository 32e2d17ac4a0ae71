"""Which CPU ray-casting kernels this process can draw without compiling them (``volumen.render._standin`` asks).

A kernel (``_warm.kernel_key``) is ready when this process drew it on the CPU (``render`` says so), when a child
of ``warm`` put it in Numba's disk cache, or when a marker says an earlier process did either: each kernel noted
ready leaves an empty file named by a hash of its key in the ray caster's kernel folder (``volumen.jit.group_folder``:
one folder per content key of the ray caster's sources, the Numba and LLVM releases and the CPU, where its
kernels are cached). So a new session with a filled cache draws its first picture on the CPU at once, as it did
before stand-ins; a marker of other sources, another build or another machine is in another folder. A marker whose
cache entry was deleted (or a cache that could not be written) costs only what a first picture cost without
stand-ins: the CPU compiles the kernel while the viewer waits. Where no marker can be written, none is.
"""

from __future__ import annotations

import hashlib
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


def marker_dir() -> Path:
    """The folder of the markers: ``ready`` in the ray caster's kernel folder (``volumen.jit.group_folder``), the
    one its cached kernels are in, so a marker never outlives the kernels of its key."""
    from ..jit import group_folder, stamped_with
    from . import optics

    return group_folder(stamped_with(optics.__file__)) / "ready"


def _marker(key: tuple) -> Path:
    return marker_dir() / hashlib.sha256(repr(key).encode()).hexdigest()[:32]


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
