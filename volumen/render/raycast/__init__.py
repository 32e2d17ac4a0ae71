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
from ._geometry import G_BOX, pack_geometry, to_index
from ._pathtrace import PathTracer
from ._sample import sample_value
from ._trace import iso_refine

# render_cpu, clear_cache and PathTracer serve volumen.render; the compiled pieces below are shared
# with other packages (endoscopy's collision march) so no formula is written twice
__all__ = ["render_cpu", "clear_cache", "PathTracer", "G_BOX", "pack_geometry", "to_index", "sample_value",
           "iso_refine"]
