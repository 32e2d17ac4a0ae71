"""CPU ray casting (Numba): kernels written once, see ``_trace.trace_pixel``.

Modules: ``_geometry`` (rays, clipping), ``_sample`` (reconstruction),
``_shade`` (lights), ``_trace`` (the marching loop), ``_precompute`` and
``_cache`` (per-volume arrays), ``_tables`` (transfer-function tables),
``_cpu`` (the parallel driver).
"""

from ._cache import clear_cache
from ._cpu import render_cpu

__all__ = ["render_cpu", "clear_cache"]
