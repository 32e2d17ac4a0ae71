"""CUDA ray casting: the shared per-ray and per-sample kernels of :mod:`volumen.render.raycast` on the GPU.

Nothing here is a second copy of a formula: the CUDA kernels (``_kernels``)
are thin grid drivers around the very ``@njit`` functions the CPU runs
(``trace_pixel``, ``trace_path`` and the lattice sweep's per-ray pieces),
which numba's CUDA target compiles as device functions from the same Python
source (:mod:`._target`). ``_device`` says whether a device is usable;
``_memory`` keeps each volume's arrays in device memory across frames;
``_lightvol`` builds the illumination volumes on the device; ``_render`` is
the backend (``render(..., backend="cuda")``) and the progressive path tracer.

Numba's CUDA support is imported only when a function here runs.
"""

from ._device import CudaUnavailableError, cuda_available, cuda_status, require_cuda
from ._memory import clear_device_cache
from ._render import CudaPathTracer, render_cuda

__all__ = ["render_cuda", "CudaPathTracer", "cuda_available", "cuda_status", "require_cuda", "CudaUnavailableError",
           "clear_device_cache"]
