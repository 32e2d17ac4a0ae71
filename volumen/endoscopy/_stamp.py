"""Numba's cache for endoscopy's kernels keyed on the ray caster's sources as well as ours.

The collision march and the unfolded view inline the ray caster's sampling and
isosurface refinement; Numba checks only the calling file, so a changed ray
caster would otherwise leave our cached kernels stale (or pointing at modules
that no longer exist). Imported first by the package.
"""

from __future__ import annotations

from pathlib import Path

from ..jit import stamp_sources
from ..render.raycast import SOURCES

stamp_sources(sorted(Path(__file__).resolve().parent.rglob("*.py")), also=SOURCES)
#: True once this package's sources are stamped
stamped = True
