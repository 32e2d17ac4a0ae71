"""The groups of sources a cached kernel is compiled from, and the content key each group's kernels are kept under.

A cached kernel inlines (or links) functions of other files: the ray caster's skeleton calls the mode pieces
of ``_composite`` / ``_iso`` / ..., the lighting of ``_shade`` and the thread counter of
:mod:`volumen.jit._threads`; endoscopy's collision march calls the ray caster's sampling; marching cubes
calls ``_mc_rows``' word helpers and freezes the tables of ``_mc_tables`` into its code. Numba checks only
the calling function's own file, so a change to one of those would leave the cached kernel stale. Each group
is declared in :mod:`._groups` and registered with :func:`stamp_sources` when :mod:`volumen.jit` is imported,
before any module that takes its decorator from it defines a kernel; every registered file then carries the key
of its whole group (:func:`source_stamp`).

What a kernel compiles to depends on its sources' contents, Numba's and LLVM's releases and the CPU, and on
nothing else: the key is a hash of exactly these (each file's path inside the package and the SHA-256 of its
bytes, the Numba and llvmlite releases, the Python release, the target triple, the CPU's name and features as
Numba's code generator sees them, ``NUMBA_CPU_NAME`` / ``NUMBA_CPU_FEATURES`` included). Not modification times:
a fresh clone, a reinstall or another checkout of the same code has the same key, and :mod:`._locate` keeps the
group's kernels in one folder per key that all of them share.
"""

from __future__ import annotations

import functools
import hashlib
import sys
from collections.abc import Iterable
from pathlib import Path

__all__ = ["stamp_sources", "stamped_with", "source_stamp", "machine"]

_PACKAGE = Path(__file__).resolve().parents[1]  # volumen/
#: the format of the key: raised when what goes into it changes
_VERSION = "volumen-kernel-key-1"
#: registered file -> the files its kernels' cache is keyed on (sorted)
_KEYS: dict[Path, tuple[Path, ...]] = {}


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
        The group: every file whose contents the kernels of ``files`` are keyed on.
    """
    own = {Path(f).resolve() for f in files}
    extra = {Path(f).resolve() for f in also}
    group = set(own) | extra
    for f in extra:
        group.update(_KEYS.get(f, ()))
    key = tuple(sorted(group))
    for f in own:
        _KEYS[f] = tuple(sorted(set(_KEYS.get(f, ())) | group))
    for f in group:
        _RECORDED.setdefault(f, hashlib.sha256(f.read_bytes()).hexdigest())
    return key


def stamped_with(path) -> tuple[Path, ...]:
    """The files whose contents the cached kernels of ``path`` are keyed on (empty: not registered)."""
    return _KEYS.get(Path(path).resolve(), ())


#: registered file -> the SHA-256 of its bytes when it was registered: the sources this process compiles from
_RECORDED: dict[Path, str] = {}


def _file_hash(path: Path) -> str:
    """SHA-256 of a registered file's bytes as they were when it was registered (a file edited while the process
    runs keeps the hash of the code the process imported: a kernel compiled later from that code is kept under
    it, never under the edited file's), of any other file as it is now."""
    recorded = _RECORDED.get(path)
    return recorded if recorded is not None else hashlib.sha256(path.read_bytes()).hexdigest()


def _name(f: Path) -> str:
    return f.relative_to(_PACKAGE).as_posix() if f.is_relative_to(_PACKAGE) else f.name


@functools.lru_cache(maxsize=1)
def machine() -> tuple:
    """What besides the sources a kernel's machine code depends on: the Numba, llvmlite and Python releases, the
    target triple and the CPU's name and features (Numba's ``NUMBA_CPU_NAME`` / ``NUMBA_CPU_FEATURES`` when set,
    as its code generator reads them)."""
    import llvmlite
    import numba
    from llvmlite import binding
    from numba.core import config

    cpu = config.CPU_NAME or binding.get_host_cpu_name()
    features = config.CPU_FEATURES if config.CPU_FEATURES is not None else binding.get_host_cpu_features().flatten()
    return (numba.__version__, llvmlite.__version__, sys.version_info[:2], binding.get_process_triple(), cpu,
            features)


def source_stamp(files: Iterable) -> str:
    """The content key of the kernels compiled from ``files``: a hex SHA-256 of each file's name and contents and
    of :func:`machine`."""
    h = hashlib.sha256(_VERSION.encode())
    h.update(repr(machine()).encode())
    for f in sorted(Path(f) for f in files):
        h.update(f"\0{_name(f)}\0{_file_hash(f)}".encode())
    return h.hexdigest()
