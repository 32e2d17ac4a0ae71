"""The sources every ray-casting kernel is compiled from, keyed together in Numba's cache (docs/design.md section 9).

The group is registered in ``render/_kernel_sources.py``, which ``render/optics.py`` imports too (the optical
model can be imported before the ray caster); this package imports this module first, before any kernel of it is
defined. Packages whose kernels call the ray caster's functions (endoscopy) add their files with ``also=SOURCES``.
"""

from __future__ import annotations

from .._kernel_sources import SOURCES

__all__ = ["SOURCES"]
