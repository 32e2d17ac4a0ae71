"""A synthetic int16 volume of any size, computed plane by plane: big out-of-core test volumes written as
OME-Zarr without ever holding the whole array.

Value at voxel ``(z, y, x)`` of a ``(nz, ny, nx)`` volume (data units, HU-like):
``1000 exp(-r^2 / (2 s^2))`` with ``r`` the distance to the centre in voxels and ``s = max(shape) / 5``, plus a
ripple ``150 sin(0.21 x) sin(0.17 y) sin(0.13 z)``, rounded to int16. Every plane is computed on its own
(``ny * nx`` float32 values at a time), so :func:`write_synthetic` keeps a few chunk-deep slabs in memory
(the OME-Zarr writer's slabs), whatever the volume's size.
"""

from __future__ import annotations

import numpy as np

from ..core import Volume
from ..io import ChunkedArray

__all__ = ["SyntheticBlob", "write_synthetic"]


class SyntheticBlob:
    """The volume above as a read-only chunked source (``shape``, ``dtype``, ``chunks``, basic slicing)."""

    def __init__(self, shape, chunks: int = 64):
        self.shape = tuple(int(n) for n in shape)
        self.dtype = np.dtype(np.int16)
        self.chunks = (int(chunks),) * 3

    def plane(self, z: int, ys: slice, xs: slice) -> np.ndarray:
        """Plane ``z`` over rows ``ys`` and columns ``xs`` (int16)."""
        c = np.array(self.shape, np.float32) / 2
        s2 = 2 * (max(self.shape) / 5.0) ** 2
        y = np.arange(*ys.indices(self.shape[1]), dtype=np.float32)[:, None]
        x = np.arange(*xs.indices(self.shape[2]), dtype=np.float32)[None, :]
        r2 = (y - c[1]) ** 2 + (x - c[2]) ** 2 + np.float32((z - c[0]) ** 2)
        d = 1000 * np.exp(-r2 / np.float32(s2)) + 150 * np.sin(0.21 * x) * np.sin(0.17 * y) * np.sin(0.13 * z)
        return np.rint(d).astype(np.int16)

    def __getitem__(self, key):
        key = tuple(key) + (slice(None),) * (3 - len(tuple(key)))
        zs = range(*key[0].indices(self.shape[0]))
        out = np.empty((len(zs), *(len(range(*k.indices(n))) for k, n in zip(key[1:], self.shape[1:],
                                                                                strict=True))), np.int16)
        for i, z in enumerate(zs):
            out[i] = self.plane(z, key[1], key[2])
        return out


def write_synthetic(path, shape, *, chunks: int = 64, spacing=(1.0, 1.0, 1.0), levels: int | None = None) -> Volume:
    """Write the synthetic volume of ``shape`` [z, y, x] as an OME-Zarr pyramid at ``path``; returns the lazy
    Volume it was written from (its data a :class:`~volumen.io.ChunkedArray` computing values on demand)."""
    from ..io import save

    vol = Volume(ChunkedArray(SyntheticBlob(shape, chunks)), spacing=spacing, modality="CT", units="HU",
                 name="synthetic")
    save(vol, path, chunks=chunks, levels=levels)
    return vol
