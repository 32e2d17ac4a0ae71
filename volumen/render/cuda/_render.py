"""The ``cuda`` backend: pack the frame as the CPU does, keep its arrays on the device, launch the kernels.

Everything up to the kernel launch is the CPU's (:func:`volumen.render.raycast.pack_frame`: settings,
tables, lights, parameters); the illumination volumes are built on the device (``_lightvol``); the arrays go
through the volume's device cache (``_memory``), so a new camera sends only the camera, a new transfer function
only its tables, a moved light only the lights and its illumination volume.
"""

from __future__ import annotations

import time

from ..raycast import Outputs, PathTracer, frame_image, pack_frame, prepare
from ._device import require_cuda
from ._lightvol import device_light_volumes
from ._memory import device_volume

__all__ = ["render_cuda", "CudaPathTracer"]

def render_cuda(scene, camera, size: tuple[int, int]):
    """Ray-cast ``scene`` on the CUDA device; the same Image as ``volumen.render.raycast.render_cpu``.

    Raises :class:`~._device.CudaUnavailableError` where no device is usable.
    ``stats["uploads"]`` names the arrays sent to the device for this frame.
    """
    device = require_cuda()  # before the kernels are imported: without numba-cuda that import fails untyped
    from numba import cuda

    from . import _kernels

    if scene.shading.mode == "pathtrace" and scene.mode == "composite":
        return CudaPathTracer(scene, camera, size).step(scene.shading.pathtrace.samples)
    t_start = time.perf_counter()
    dev = device_volume(prepare(scene.volume))
    dev.begin_frame()
    f = pack_frame(scene, camera, size, build_light_volumes=device_light_volumes)
    w, h = f.size
    t = time.perf_counter()
    arrays = f.device_arrays(dev.put)
    timings = dict(f.timings, upload=time.perf_counter() - t)
    out = dev.outputs(w, h)
    t = time.perf_counter()
    blocks, threads = _kernels.grid_2d(w, h)
    _kernels.trace[blocks, threads](arrays, f.settings, out, f.mode, f.light)
    cuda.synchronize()
    timings["kernel"] = time.perf_counter() - t
    host = Outputs(*(x.copy_to_host() for x in out))
    timings["total"] = time.perf_counter() - t_start
    return frame_image(scene, f, host, timings, {"backend": "cuda", "device": device, "uploads": list(dev.uploads)})


class CudaPathTracer(PathTracer):
    """:class:`~volumen.render.PathTracer` on the CUDA device: the same samples (same random streams), so the
    same pixels; the running sums stay on the device and come back at each :meth:`step`."""

    backend = "cuda"

    def __init__(self, scene, camera, size):
        require_cuda()
        super().__init__(scene, camera, size)
        from numba import cuda

        f = self.frame
        self._dev = device_volume(f.prep)
        self._dev.begin_frame()
        self._arrays = f.device_arrays(self._dev.put)
        self._acc = cuda.to_device(self.acc)
        self._alpha = cuda.to_device(self.coverage)
        self._feat = cuda.to_device(self.features)

    def _accumulate(self, s0: int, s1: int) -> None:
        from numba import cuda

        from . import _kernels

        w, h = self.frame.size
        blocks, threads = _kernels.grid_2d(w, h)
        _kernels.paths[blocks, threads](int(s0), int(s1), self._arrays, self.frame.settings, self._acc, self._alpha,
                                           self._feat)
        cuda.synchronize()
        self._acc.copy_to_host(self.acc)
        self._alpha.copy_to_host(self.coverage)
        self._feat.copy_to_host(self.features)

    def reset(self) -> None:
        """Forget the accumulated samples (on the device too)."""
        super().reset()
        self._acc.copy_to_device(self.acc)
