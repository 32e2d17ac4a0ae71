"""A least-recently-used cache of whole decoded chunks, and of what a reader derives from them, bounded in bytes:
what an out-of-core renderer reads through.

:class:`ChunkCache` stands in front of a chunked source (a ``zarr.Array``)
and answers the slices :class:`~volumen.io._chunked.ChunkedArray` asks for,
each inside one chunk, from whole chunks kept decoded in least-recently-used
order; a chunk missing is read from the store and decoded (``misses``).
Beside the chunks it keeps *derived* entries a reader puts there with their
size (:meth:`ChunkCache.keep`; the out-of-core renderer keeps a brick's
samples with its normal codes, skip blocks and per-transfer-function tables):
they share the chunks' order and byte budget, and are dropped with them,
oldest first, while the kept bytes would pass ``max_bytes`` (``peak``: the
most bytes held at once; one chunk at least). A derived entry is kept only
where that drops nothing the current frame (:meth:`ChunkCache.new_frame`) has
used: when the cache is too small for one frame, the chunks keep the room they
had. :meth:`ChunkedArray.cached <volumen.io._chunked.ChunkedArray.cached>`
gives a view read through the source's cache.
"""

from __future__ import annotations

from collections import OrderedDict

import numpy as np

__all__ = ["ChunkCache"]


class ChunkCache:
    """Whole decoded chunks of a chunked source, and derived entries, kept in least-recently-used order, at most
    ``max_bytes`` of them (one chunk at least). Takes slices that lie inside one chunk, as
    :class:`ChunkedArray` asks for them.

    Attributes
    ----------
    misses, hits : int
        Chunks read (and decoded) from the source, chunks answered from the cache.
    derived_hits : int
        Derived entries found (:meth:`derived`).
    bytes, peak : int
        Bytes held now, and at most.
    """

    def __init__(self, source, max_bytes: int):
        self.source, self.max_bytes = source, int(max_bytes)
        self.shape, self.dtype, self.chunks = tuple(source.shape), source.dtype, tuple(source.chunks)
        self._lru: OrderedDict = OrderedDict()  # key -> [value, nbytes, frame last used]
        self.bytes = self.peak = self.misses = self.hits = self.derived_hits = self.frame = 0

    def new_frame(self) -> None:
        """Start a frame: what it uses from now on is not dropped to keep a derived entry."""
        self.frame += 1

    def _touch(self, key):
        entry = self._lru.get(key)
        if entry is not None:
            self._lru.move_to_end(key)
            entry[2] = self.frame
        return entry

    def _drop_for(self, nbytes: int, spare_frame: bool) -> bool:
        """Drop the oldest entries until ``nbytes`` more fit; with ``spare_frame``, refuse (False) rather than
        drop an entry the current frame used."""
        if spare_frame:
            need, free = self.bytes + nbytes - self.max_bytes, 0
            for _, size, frame in self._lru.values():
                if free >= need:
                    break
                if frame == self.frame:
                    return False
                free += size
        while self._lru and self.bytes + nbytes > self.max_bytes:
            self.bytes -= self._lru.popitem(last=False)[1][1]
        return True

    def _put(self, key, value, nbytes: int) -> None:
        self._lru[key] = [value, int(nbytes), self.frame]
        self.bytes += int(nbytes)
        self.peak = max(self.peak, self.bytes)

    def __getitem__(self, key):
        idx = tuple(s.start // c for s, c in zip(key, self.chunks, strict=True))
        entry = self._touch(idx)
        if entry is None:
            self.misses += 1
            whole = tuple(slice(i * c, min((i + 1) * c, n)) for i, c, n in zip(idx, self.chunks, self.shape,
                                                                              strict=True))
            blk = np.asarray(self.source[whole])
            self._drop_for(blk.nbytes, False)
            self._put(idx, blk, blk.nbytes)
        else:
            self.hits += 1
            blk = entry[0]
        return blk[tuple(slice(s.start - i * c, s.stop - i * c) for s, i, c in zip(key, idx, self.chunks,
                                                                                  strict=True))]

    def derived(self, key):
        """The derived entry kept under ``key`` (a tuple starting with a string, apart from the chunks' index
        tuples), or None."""
        entry = self._touch(key)
        if entry is None:
            return None
        self.derived_hits += 1
        return entry[0]

    def keep(self, key, value, nbytes: int) -> bool:
        """Keep ``value`` (``nbytes`` bytes) under ``key`` (replacing what was there: its size may have grown),
        dropping the oldest entries the current frame did not use; False (nothing kept) where it does not fit."""
        old = self._lru.pop(key, None)
        if old is not None:
            self.bytes -= old[1]
        if nbytes > self.max_bytes or not self._drop_for(int(nbytes), True):
            return False
        self._put(key, value, nbytes)
        return True
