"""The sources marching cubes' kernels are compiled from, keyed together in Numba's cache (docs/design.md section 9).

``_mc_kernel`` inlines ``_mc_rows``' word helpers and freezes ``_mc_tables``' arrays into its machine code;
Numba checks only a kernel's own file, so the ``_mc_*`` files are one group, registered before any of their
kernels is defined (each of them imports this first; ``import volumen.surface`` stays free of Numba).
"""

from __future__ import annotations

from pathlib import Path

from ..jit import stamp_sources

__all__ = ["SOURCES"]

#: the group: every ``_mc_*.py`` file of this package
SOURCES = stamp_sources(sorted(Path(__file__).resolve().parent.glob("_mc_*.py")))
