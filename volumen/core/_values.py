"""A strided sample of a volume's values: what the decisions about a whole volume read (is it a CT, where do its
values lie) without reading every voxel of a large or chunked one. A chunked volume's sample (three planes read
from its store) is kept for the last few arrays asked about: each decision asks again."""

from __future__ import annotations

import weakref

import numpy as np

from ._volume import is_chunked

__all__ = ["strided_values", "SAMPLE"]

#: about this many voxels are read
SAMPLE = 200_000
#: id(chunked array) -> (weak reference, its sample), the last few
_KEPT: dict = {}


def strided_values(volume) -> np.ndarray:
    """The values of every k-th voxel along each axis (k for at most about :data:`SAMPLE` of them), flat; of a
    chunked volume, of every k-th voxel along y and x of three planes (a quarter, half and three quarters along z:
    each of them, only the chunks they cross are read)."""
    data = volume.data
    if is_chunked(data):
        hit = _KEPT.get(id(data))
        if hit is not None and hit[0]() is data:
            return hit[1]
        nz = data.shape[0]
        planes = np.stack([np.asarray(data[k]) for k in sorted({nz // 4, nz // 2, (3 * nz) // 4})])
        step = max(1, int(round((planes.size / SAMPLE) ** 0.5)))
        sample = planes[:, ::step, ::step].ravel()
        sample.flags.writeable = False
        _KEPT[id(data)] = (weakref.ref(data), sample)
        for key in list(_KEPT)[:-4]:  # the oldest past four (the app's threads may both be here)
            _KEPT.pop(key, None)
        return sample
    step = max(1, int(round((data.size / SAMPLE) ** (1.0 / 3.0))))
    return np.asarray(data[::step, ::step, ::step]).ravel()
