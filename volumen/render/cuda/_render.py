"""The ``cuda`` backend: pack the frame as the CPU does, keep its arrays on the device, launch the kernels.

Everything up to the kernel launch is the CPU's (:func:`~volumen.render.raycast._pack.pack_frame`: settings,
tables, lights, parameters); the illumination volumes are built on the device (``_lightvol``); the arrays go
through the volume's device cache (``_memory``), so a new camera sends only the camera, a new transfer function
only its tables, a moved light only the lights and its illumination volume.
"""

from __future__ import annotations

import time

import numpy as np

from ..raycast._cache import prepare
from ..raycast._pack import pack_frame
from ..raycast._pathtrace import PathTracer
from ..raycast._trace import FAR
from ._device import require_cuda
from ._lightvol import device_light_volumes
from ._memory import device_volume

__all__ = ["render_cuda", "CudaPathTracer"]

#: the packed arrays of a frame that stay on the device between frames (large ones keyed by object identity)
_STATIC = ("vol", "nrm", "bmin", "bmax")


def _device_args(f, dev):
    """The device copies of ``f.args()`` (names as ``trace_pixel``'s arguments)."""
    names = ("cam", "geo", "planes", "vol", "nrm", "lut", "pre", "glut", "bflag", "bmin", "bmax", "lights", "lvm",
             "lvd", "sig", "prm", "iprm")
    return tuple(dev.put(name, a, same_object=name in _STATIC) for name, a in zip(names, f.args()))


def render_cuda(scene, camera, size: tuple[int, int]):
    """Ray-cast ``scene`` on the CUDA device; the same Image as ``volumen.render.raycast.render_cpu``.

    Raises :class:`~._device.CudaUnavailableError` where no device is usable.
    ``stats["uploads"]`` names the arrays sent to the device for this frame.
    """
    from numba import cuda

    from ...core import Image
    from . import _kernels

    device = require_cuda()
    if scene.shading.mode == "pathtrace" and scene.mode == "composite":
        return CudaPathTracer(scene, camera, size).step(scene.shading.pt_samples)
    t_start = time.perf_counter()
    w, h = (int(s) for s in size)
    dev = device_volume(prepare(scene.volume))
    dev.begin_frame()
    f = pack_frame(scene, camera, (w, h), build_light_volumes=device_light_volumes)
    timings = f.timings
    t = time.perf_counter()
    args = _device_args(f, dev)
    timings["upload"] = time.perf_counter() - t
    rgba = cuda.device_array((h, w, 4), np.float32)
    depth = cuda.device_array((h, w), np.float32)
    value = cuda.device_array((h, w), np.float32)
    nsamp = cuda.device_array((h, w), np.int32)
    t = time.perf_counter()
    blocks, threads = _kernels.grid_2d(w, h)
    _kernels.trace[blocks, threads](*args, rgba, depth, value, nsamp)
    cuda.synchronize()
    timings["kernel"] = time.perf_counter() - t
    rgba, depth, value, nsamp = rgba.copy_to_host(), depth.copy_to_host(), value.copy_to_host(), nsamp.copy_to_host()
    depth[depth >= 0.5 * FAR] = np.inf
    value[value >= 0.5 * FAR] = np.nan
    timings["total"] = time.perf_counter() - t_start
    mode = scene.mode
    stats = {"timings": timings, "samples": int(nsamp.sum(dtype=np.int64)), "rays": w * h,
             "rays_hit": int(np.count_nonzero(nsamp)), "backend": "cuda", "device": device, "mode": mode,
             "shading": scene.shading.mode, "step_mm": f.ds, "reference_step_mm": f.ds0,
             "light_volumes_built": f.light_volumes_built, "uploads": list(dev.uploads)}
    return Image(rgba=rgba, depth=depth, stats=stats, value=value if mode in ("mip", "minip", "average") else None)


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
        names = ("cam", "geo", "planes", "vol", "lut", "sig", "lights", "prm", "iprm")
        self._args = tuple(self._dev.put(n, getattr(f, n), same_object=n in _STATIC) for n in names)
        self._acc = cuda.to_device(self.acc)

    def _accumulate(self, s0: int, s1: int) -> None:
        from numba import cuda

        from . import _kernels

        w, h = self.frame.size
        blocks, threads = _kernels.grid_2d(w, h)
        cam, geo, planes, vol, lut, sig, lights, prm, iprm = self._args
        _kernels.paths[blocks, threads](int(s0), int(s1), cam, geo, planes, vol, lut, sig, lights, prm, iprm,
                                         float(self.smaj), self._acc)
        cuda.synchronize()
        self._acc.copy_to_host(self.acc)

    def reset(self) -> None:
        """Forget the accumulated samples (on the device too)."""
        super().reset()
        self._acc.copy_to_device(self.acc)
