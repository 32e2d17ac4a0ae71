"""The sources every ray-casting kernel is compiled from, registered as one group in Numba's cache stamps
(``volumen.jit``, docs/design.md section 9) before any of them defines a compiled function.

The marching skeleton (``raycast``) inlines the mode pieces, the lighting, the optical model (``optics.py``) and
the thread driver's work counter (``volumen/jit/_threads.py``) and the prefetch hint
(``volumen/jit/_prefetch.py``), and reads the lighting model's constants
(``volumen/core/_lighting.py``: ``FACING``, frozen into the machine code); Numba checks only a kernel's own
file, so all of them are keyed together. ``optics`` and ``raycast`` both import this module before any compiled
function: ``optics`` can be imported on its own, before the ray caster, and its functions must be stamped all
the same.
"""

from __future__ import annotations

from pathlib import Path

from ..core import _lighting
from ..jit import _prefetch, _threads, stamp_sources

__all__ = ["SOURCES"]

_HERE = Path(__file__).resolve().parent
#: the group: every file of the ray caster, the optical model, the thread driver, the prefetch hint and the lighting
#: constants
SOURCES = stamp_sources([*sorted((_HERE / "raycast").glob("*.py")), _HERE / "optics.py"],
                        also=[_threads.__file__, _prefetch.__file__, _lighting.__file__])
