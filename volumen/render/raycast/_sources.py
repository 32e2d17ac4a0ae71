"""The sources every ray-casting kernel is compiled from, keyed together in Numba's cache (docs/design.md section 9).

The marching skeleton inlines the mode pieces, the lighting, ``render/optics.py`` and the thread driver's
work counter (``volumen/jit/_threads.py``); Numba checks only a kernel's own file, so all of them are
registered as one group before any kernel of this package is defined (the package imports this first).
Packages whose kernels call the ray caster's functions (endoscopy) add their files with ``also=SOURCES``.
"""

from __future__ import annotations

from pathlib import Path

from ...jit import _threads, stamp_sources

__all__ = ["SOURCES"]

_HERE = Path(__file__).resolve().parent
#: the group: every file of this package, the optical model and the thread driver
SOURCES = stamp_sources([*sorted(_HERE.glob("*.py")), _HERE.parent / "optics.py"], also=[_threads.__file__])
