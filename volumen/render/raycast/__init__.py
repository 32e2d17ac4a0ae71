"""CPU ray casting (Numba): kernels written once, see ``_trace.trace_pixel``.

Modules: ``_geometry`` (rays, clipping), ``_sample`` (reconstruction),
``_shade`` (lights, every shading model), ``_shadow`` (direct shadow rays),
``_lightvol`` (illumination volumes), ``_scatter`` (the scattering medium),
``_trace`` (the marching loop), ``_pathtrace`` (progressive path tracing),
``_precompute`` and ``_cache`` (per-volume arrays), ``_tables``
(transfer-function tables), ``_params`` (packed parameter layouts), ``_pack``
(scene -> arrays), ``_cpu`` (the parallel driver).
"""

from ._cache import clear_cache
from ._cpu import render_cpu
from ._pathtrace import PathTracer

__all__ = ["render_cpu", "clear_cache", "PathTracer"]
