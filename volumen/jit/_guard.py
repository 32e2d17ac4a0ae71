"""The fence around volumen's patches to Numba's private internals: the tested range of Numba releases.

``jit/_inlining.py`` patches three internals of Numba's inliner and dispatcher, and
:mod:`._stamp` a fourth (the cache locators). Private code changes without notice, so the inliner patches
apply only to the Numba releases they were tested with (:data:`NUMBA_TESTED`, the same range as
``pyproject.toml``'s ``numba`` requirement; ``tests/render/test_inlining.py`` compiles a kernel with and
without them). Outside that range, or with ``VOLUMEN_NUMBA_PATCHES=0`` in the environment, they stand down:
every kernel compiles as plain Numba compiles it (the same machine code, only slower to build), and a
warning says so once.
"""

from __future__ import annotations

import os
import warnings

__all__ = ["NUMBA_TESTED", "NUMBA_CUDA_TESTED", "ENV", "numba_version", "in_tested_range", "patches_allowed",
           "cuda_patches_allowed"]

#: Numba releases the patches were tested with: ``[first, end)`` (pyproject.toml: ``numba>=first,<end``)
NUMBA_TESTED = ((0, 61), (0, 69))
#: numba-cuda releases the same patches were tested with in numba-cuda's own copy of Numba's compiler
#: (``_inlining.install_cuda``): ``[first, end)``
NUMBA_CUDA_TESTED = ((0, 30), (0, 31))
#: set to ``0`` to compile without volumen's patches (a check, or a Numba regression suspected)
ENV = "VOLUMEN_NUMBA_PATCHES"
_warned: set[str] = set()


def numba_version() -> tuple[int, ...]:
    """The installed Numba's release as integers (``"0.68.1"`` -> ``(0, 68, 1)``; a suffix is dropped)."""
    import numba

    return _release(numba.__version__)


def _release(text: str) -> tuple[int, ...]:
    parts = []
    for p in text.split("+")[0].split("."):
        digits = "".join(c for c in p if c.isdigit())
        if not digits:
            break
        parts.append(int(digits))
        if digits != p:
            break
    return tuple(parts)


def in_tested_range(version: tuple[int, ...] | None = None) -> bool:
    """Whether ``version`` (default: the installed Numba's) lies in :data:`NUMBA_TESTED`."""
    return _within(numba_version() if version is None else tuple(version), NUMBA_TESTED)


def _within(version: tuple[int, ...], tested) -> bool:
    first, end = tested
    return first <= version[:2] < end


def _warn_once(key: str, message: str) -> None:
    if key not in _warned:
        _warned.add(key)
        warnings.warn(message, RuntimeWarning, stacklevel=4)  # the caller of (cuda_)patches_allowed


def _fenced(name: str, text: str, inside: bool, tested) -> bool:
    """``inside``; when not, warns once (per ``name``) that release ``text`` of ``name`` is outside ``tested``."""
    if not inside:
        first, end = (".".join(map(str, v)) for v in tested)
        _warn_once(name, f"{name} {text} is outside the range volumen's patches to its compiler were tested with "
                         f"(>= {first}, < {end}): they stand down, so its kernels compile correctly but more slowly "
                         f"the first time (docs/design.md section 9)")
    return inside


def patches_allowed() -> bool:
    """Whether the patches may apply here: the Numba release is in the tested range and ``VOLUMEN_NUMBA_PATCHES``
    is not ``0``. Outside the range, warns once that the kernels compile unpatched (correct, slower)."""
    if os.environ.get(ENV, "1").strip() == "0":
        return False
    import numba

    return _fenced("Numba", numba.__version__, in_tested_range(), NUMBA_TESTED)


def cuda_patches_allowed() -> bool:
    """Whether the patches may apply to numba-cuda's copy of the compiler: :func:`patches_allowed`, and the installed
    numba-cuda in :data:`NUMBA_CUDA_TESTED` (outside it, warns once that the CUDA kernels compile unpatched)."""
    if not patches_allowed():
        return False
    import numba_cuda

    text = numba_cuda.__version__
    return _fenced("numba-cuda", text, _within(_release(text), NUMBA_CUDA_TESTED), NUMBA_CUDA_TESTED)
