"""A least-recently-used cache of whole chunks, bounded in bytes: what an out-of-core renderer reads through.

:class:`ChunkCache` stands in front of a chunked source (a ``zarr.Array``)
and answers the slices :class:`~volumen.io._chunked.ChunkedArray` asks for,
each inside one chunk, from whole chunks kept in least-recently-used order; a
chunk missing is read from the source (``misses``: reads from the store) and
the oldest are dropped while the kept bytes would pass ``max_bytes``
(``peak``: the most bytes held at once; one chunk at least).
:meth:`ChunkedArray.cached <volumen.io._chunked.ChunkedArray.cached>` gives
a view read through one.
"""

from __future__ import annotations

from collections import OrderedDict

import numpy as np

__all__ = ["ChunkCache"]


class ChunkCache:
    """Whole chunks of a chunked source kept in least-recently-used order, at most ``max_bytes`` of them
    (one chunk at least). Takes slices that lie inside one chunk, as :class:`ChunkedArray` asks for them."""

    def __init__(self, source, max_bytes: int):
        self.source, self.max_bytes = source, int(max_bytes)
        self.shape, self.dtype, self.chunks = tuple(source.shape), source.dtype, tuple(source.chunks)
        self._lru: OrderedDict = OrderedDict()
        self.bytes = self.peak = self.misses = self.hits = 0

    def __getitem__(self, key):
        idx = tuple(s.start // c for s, c in zip(key, self.chunks, strict=True))
        blk = self._lru.get(idx)
        if blk is None:
            self.misses += 1
            whole = tuple(slice(i * c, min((i + 1) * c, n)) for i, c, n in zip(idx, self.chunks, self.shape,
                                                                              strict=True))
            blk = np.asarray(self.source[whole])
            while self._lru and self.bytes + blk.nbytes > self.max_bytes:
                self.bytes -= self._lru.popitem(last=False)[1].nbytes
            self._lru[idx] = blk
            self.bytes += blk.nbytes
            self.peak = max(self.peak, self.bytes)
        else:
            self.hits += 1
            self._lru.move_to_end(idx)
        return blk[tuple(slice(s.start - i * c, s.stop - i * c) for s, i, c in zip(key, idx, self.chunks,
                                                                                  strict=True))]
