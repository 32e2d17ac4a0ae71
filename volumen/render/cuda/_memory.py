"""Device memory: each volume's arrays uploaded once and kept across frames, small tables only when they change.

The cache lives on the volume's prepared precomputations (``volumen.render.raycast.prepare``)
(attribute ``device``), so it is keyed exactly like the CPU cache (the Volume
object, its data array, shape, dtype and affine) and goes when that is
rebuilt or cleared. Large arrays (normalized volume, normals, block grids)
are the Prepared's own objects and are uploaded the first time they are
seen; per-frame tables (transfer-function tables, lights, camera,
parameters) are compared with the copy sent last time under the same name
and sent only when they differ. ``uploads`` names what the last frame sent.
"""

from __future__ import annotations

import numpy as np

__all__ = ["DeviceVolume", "device_volume", "clear_device_cache", "permuted"]


class DeviceVolume:
    """The device arrays of one prepared volume.

    Attributes
    ----------
    uploads : list of str
        Names of the arrays sent to the device since :meth:`begin_frame`.
    light_set : object or None
        The illumination volumes on the device (``_lightvol``).
    """

    def __init__(self):
        self._arrays: dict = {}
        self._outputs = None
        self.uploads: list[str] = []
        self.light_set = None

    def outputs(self, w: int, h: int):
        """The kernels' :class:`~volumen.render.raycast.Outputs` for a ``w`` x ``h`` picture, kept on the device
        while the size stays (every kernel writes every pixel, as into the CPU's ``numpy.empty`` ones)."""
        from numba import cuda

        from ..raycast import Outputs

        if self._outputs is None or self._outputs.depth.shape != (h, w):
            self._outputs = Outputs.empty(w, h, cuda.device_array)
        return self._outputs

    def begin_frame(self) -> None:
        """Start counting uploads anew."""
        self.uploads = []

    def put(self, name: str, host: np.ndarray, same_object: bool = False):
        """The device copy of ``host`` stored under ``name``, sent only when it changed.

        ``same_object``: ``host`` is a cached array that never changes in
        place (the normalized volume, normals, blocks): reuse the device copy
        while it is the same object, without comparing contents.
        """
        from numba import cuda

        if not isinstance(host, np.ndarray):  # already on the device (illumination volumes)
            return host
        old = self._arrays.get(name)
        if old is not None:
            prev, dev = old
            if prev is host:
                return dev
            if not same_object and prev.shape == host.shape and prev.dtype == host.dtype and np.array_equal(prev, host):
                return dev
            if prev.shape == host.shape and prev.dtype == host.dtype:
                dev.copy_to_device(np.ascontiguousarray(host))
                self._arrays[name] = (host if same_object else host.copy(), dev)
                self.uploads.append(name)
                return dev
        dev = cuda.to_device(np.ascontiguousarray(host))
        self._arrays[name] = (host if same_object else host.copy(), dev)
        self.uploads.append(name)
        return dev

    def nbytes(self) -> int:
        """Bytes held on the device (cached arrays and illumination volumes)."""
        n = sum(int(d.size * d.dtype.itemsize) for _, d in self._arrays.values())
        if self.light_set is not None:
            n += int(self.light_set.lvd.size * 4)
        return n


def device_volume(prep) -> DeviceVolume:
    """The :class:`DeviceVolume` of a Prepared volume (made on first use)."""
    dev = getattr(prep, "device", None)
    if dev is None:
        dev = prep.device = DeviceVolume()
    return dev


def clear_device_cache(volume=None) -> None:
    """Free the device arrays of ``volume`` (or of every cached volume); the CPU cache stays."""
    from ..raycast import prepared_volumes

    for p in prepared_volumes(volume):
        if getattr(p, "device", None) is not None:
            p.device = None


def permuted(dev_array, axes):
    """A view of a device array with its axes permuted (no copy): ``numpy.transpose`` on the device."""
    if tuple(axes) == tuple(range(dev_array.ndim)):
        return dev_array
    if hasattr(dev_array, "_ary"):  # the simulator's fake device array wraps a numpy array
        return type(dev_array)(np.transpose(dev_array._ary, axes))
    from numba.cuda.cudadrv.devicearray import DeviceNDArray

    shape = tuple(dev_array.shape[a] for a in axes)
    strides = tuple(dev_array.strides[a] for a in axes)
    return DeviceNDArray(shape, strides, dev_array.dtype, gpu_data=dev_array.gpu_data)
