"""The fence around volumen's patches to Numba's private internals: the tested range of Numba releases.

``render/raycast/_inlining.py`` patches three internals of Numba's inliner and dispatcher, and
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
    v = numba_version() if version is None else tuple(version)
    first, end = NUMBA_TESTED
    return first <= v[:2] < end


def _warn_once(key: str, message: str) -> None:
    if key not in _warned:
        _warned.add(key)
        warnings.warn(message, RuntimeWarning, stacklevel=3)


def patches_allowed() -> bool:
    """Whether the patches may apply here: the Numba release is in the tested range and ``VOLUMEN_NUMBA_PATCHES``
    is not ``0``. Outside the range, warns once that the kernels compile unpatched (correct, slower)."""
    if os.environ.get(ENV, "1").strip() == "0":
        return False
    if not in_tested_range():
        import numba

        first, end = (".".join(map(str, v)) for v in NUMBA_TESTED)
        _warn_once("range", f"Numba {numba.__version__} is outside the range volumen's patches to Numba's compiler "
                            f"were tested with (>= {first}, < {end}): they stand down, so kernels compile correctly "
                            f"but more slowly the first time (docs/design.md section 9)")
        return False
    return True


def cuda_patches_allowed() -> bool:
    """Whether the patches may apply to numba-cuda's copy of the compiler: :func:`patches_allowed`, and the installed
    numba-cuda in :data:`NUMBA_CUDA_TESTED` (outside it, warns once that the CUDA kernels compile unpatched)."""
    if not patches_allowed():
        return False
    import numba_cuda

    first, end = NUMBA_CUDA_TESTED
    if first <= _release(numba_cuda.__version__)[:2] < end:
        return True
    lo, hi = (".".join(map(str, v)) for v in NUMBA_CUDA_TESTED)
    _warn_once("cuda-range", f"numba-cuda {numba_cuda.__version__} is outside the range volumen's patches to its "
                             f"compiler were tested with (>= {lo}, < {hi}): they stand down, so CUDA kernels compile "
                             f"correctly but more slowly the first time (docs/design.md section 9)")
    return False
