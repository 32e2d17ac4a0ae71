"""A lazy view of a chunked array (Zarr): indexed [z, y, x] like NumPy, reading only the chunks a request touches.

:class:`ChunkedArray` is what a :class:`~volumen.core.Volume` holds as its
``data`` when it is backed by a chunked store: basic slicing and transposing
give new lazy views (no reading); an integer index, ``np.asarray`` or
:meth:`ChunkedArray.read` read the chunks the result needs, one by one, and
count them in ``stats["chunk_reads"]`` (shared by every view of one source).
A view of the whole source also answers the source's per-chunk value ranges
(:attr:`ChunkedArray.chunk_ranges`, stored by the OME-Zarr writer), and
:meth:`ChunkedArray.cached` reads it through the source's bounded :class:`~._chunk_cache.ChunkCache`:
what the out-of-core renderer (``volumen.render.bricked``) asks of a chunked volume.
"""

from __future__ import annotations

import itertools

import numpy as np

from ._chunk_cache import ChunkCache

__all__ = ["ChunkedArray"]


class ChunkedArray:
    """A lazy, read-only view ``[z, y, x]`` of a chunked source (anything with ``shape``, ``dtype``, ``chunks``
    and NumPy basic slicing, e.g. a ``zarr.Array``).

    Parameters
    ----------
    source : zarr.Array or similar
    perm, start, step, shape : per view axis, optional
        View axis ``a`` reads source axis ``perm[a]`` at ``start[a] + step[a] * n``, ``n < shape[a]``.
    stats : dict, optional
        Counters shared by the views of one source (``chunk_reads``).
    ranges : (cmin, cmax), optional
        The source's per-chunk minima and maxima (arrays over its chunk grid, source axis order).
    """

    __volumen_chunked__ = True

    def __init__(self, source, perm=None, start=None, step=None, shape=None, stats=None, ranges=None):
        nd = len(source.shape)
        self.source = source
        self.perm = tuple(range(nd)) if perm is None else tuple(perm)
        self.start = (0,) * nd if start is None else tuple(int(s) for s in start)
        self.step = (1,) * nd if step is None else tuple(int(s) for s in step)
        self.shape = tuple(int(n) for n in source.shape) if shape is None else tuple(int(n) for n in shape)
        self.stats = {"chunk_reads": 0} if stats is None else stats
        self.ranges = ranges

    # -- array protocol ---------------------------------------------------------
    @property
    def dtype(self) -> np.dtype:
        return np.dtype(self.source.dtype)

    @property
    def ndim(self) -> int:
        return len(self.shape)

    @property
    def size(self) -> int:
        return int(np.prod(self.shape))

    @property
    def nbytes(self) -> int:
        return self.size * self.dtype.itemsize

    @property
    def chunks(self) -> tuple[int, ...]:
        """The source's chunk shape (source axis order)."""
        return tuple(int(c) for c in self.source.chunks)

    @property
    def chunk_ranges(self):
        """``(cmin, cmax)``: per chunk of the source (arrays over its chunk grid) the least and greatest value,
        when stored and this view is the whole source in its own order; else None."""
        whole = (self.perm == tuple(range(self.ndim)) and not any(self.start) and set(self.step) == {1}
                 and self.shape == tuple(int(n) for n in self.source.shape))
        return self.ranges if whole else None

    def cached(self, max_bytes: int) -> tuple[ChunkedArray, ChunkCache]:
        """This view read through the source's :class:`~._chunk_cache.ChunkCache` of at most ``max_bytes`` (one
        chunk at least), and the cache (its ``misses``: chunks read from the store; ``peak``: bytes held at most).

        The cache is kept with the views of one source (one ``volumen.load``), so the next frames find the
        chunks decoded and what the renderer derived from them; another ``max_bytes`` starts a new one."""
        cache = self.stats.get("cache")
        if cache is None or cache.max_bytes != int(max_bytes):
            self.stats["cache"] = cache = ChunkCache(self.source, max_bytes)
        return ChunkedArray(cache, self.perm, self.start, self.step, self.shape, ranges=self.ranges), cache

    def __len__(self) -> int:
        return self.shape[0]

    def __repr__(self) -> str:
        return f"ChunkedArray(shape={self.shape}, dtype={self.dtype}, chunks={self.chunks})"

    def __array__(self, dtype=None, copy=None):
        a = self.read()
        return a if dtype is None else a.astype(dtype, copy=False)

    def transpose(self, *axes) -> ChunkedArray:
        axes = tuple(axes[0]) if len(axes) == 1 and not isinstance(axes[0], int) else tuple(axes)
        if not axes:
            axes = tuple(reversed(range(self.ndim)))
        return ChunkedArray(self.source, [self.perm[a] for a in axes], [self.start[a] for a in axes],
                            [self.step[a] for a in axes], [self.shape[a] for a in axes], self.stats, self.ranges)

    def repeat(self, repeats: int, axis: int) -> ChunkedArray:
        """A lazy view holding the sample of an axis of one ``repeats`` times (``np.repeat`` calls it: a single
        plane's slab, :func:`volumen.core.slab_grid`); nothing is read."""
        axis = int(axis) % self.ndim
        if self.shape[axis] != 1:
            raise ValueError(f"a ChunkedArray repeats an axis of one sample, axis {axis} has {self.shape[axis]}")
        step, shape = list(self.step), list(self.shape)
        step[axis], shape[axis] = 0, int(repeats)
        return ChunkedArray(self.source, self.perm, self.start, step, shape, self.stats, self.ranges)

    def __getitem__(self, key):
        key = key if isinstance(key, tuple) else (key,)
        if any(k is Ellipsis for k in key):
            i = key.index(Ellipsis)
            key = key[:i] + (slice(None),) * (self.ndim - len(key) + 1) + key[i + 1:]
        key = key + (slice(None),) * (self.ndim - len(key))
        if len(key) != self.ndim:
            raise IndexError(f"too many indices for a {self.ndim}-d array")
        start, step, shape, drop = list(self.start), list(self.step), list(self.shape), []
        for a, k in enumerate(key):
            if isinstance(k, slice):
                r = range(self.shape[a])[k]
                start[a], step[a], shape[a] = self.start[a] + self.step[a] * r.start, self.step[a] * r.step, len(r)
            elif isinstance(k, (int, np.integer)):
                n = int(k) + (self.shape[a] if k < 0 else 0)
                if not 0 <= n < self.shape[a]:
                    raise IndexError(f"index {int(k)} is out of bounds for axis {a} with size {self.shape[a]}")
                start[a], step[a], shape[a] = self.start[a] + self.step[a] * n, 1, 1
                drop.append(a)
            else:
                raise TypeError(f"ChunkedArray takes ints and slices, got {type(k).__name__}")
        view = ChunkedArray(self.source, self.perm, start, step, shape, self.stats, self.ranges)
        if not drop:
            return view
        return view.read().squeeze(axis=tuple(drop))

    # -- reading ----------------------------------------------------------------
    def _source_ranges(self):
        """Per source axis: (first, last + 1) read, and the view axis that maps to it."""
        nd = self.ndim
        rng = [(0, 1)] * nd
        for a in range(nd):
            lo = self.start[a]
            hi = self.start[a] + self.step[a] * (self.shape[a] - 1)
            rng[self.perm[a]] = (min(lo, hi), max(lo, hi) + 1)
        return rng

    def read(self) -> np.ndarray:
        """The view's values as a C-contiguous NumPy array, read chunk by chunk."""
        if 0 in self.shape:
            return np.empty(self.shape, self.dtype)
        rng = self._source_ranges()
        box = np.empty([hi - lo for lo, hi in rng], self.dtype)
        grids = [range(lo // c, (hi - 1) // c + 1) for (lo, hi), c in zip(rng, self.chunks, strict=True)]
        for idx in itertools.product(*grids):
            src = tuple(slice(max(i * c, lo), min((i + 1) * c, hi)) for i, c, (lo, hi) in
                        zip(idx, self.chunks, rng, strict=True))
            dst = tuple(slice(s.start - lo, s.stop - lo) for s, (lo, _) in zip(src, rng, strict=True))
            box[dst] = self.source[src]
            self.stats["chunk_reads"] += 1
        # pick the view's samples in source order, then put the axes in view order
        sel = [slice(None)] * self.ndim
        for a in range(self.ndim):
            s0, step = self.start[a] - rng[self.perm[a]][0], self.step[a] or 1  # step 0: one sample, repeated
            stop = s0 + step * (self.shape[a] if self.step[a] else 1)
            sel[self.perm[a]] = slice(s0, stop if stop >= 0 else None, step)
        view = np.transpose(box[tuple(sel)], self.perm)
        return np.ascontiguousarray(np.broadcast_to(view, self.shape))

    # -- reductions the Volume uses (streamed chunk by chunk) ------------------
    def _reduce(self, name):
        key = (name, self.perm, self.start, self.step, self.shape)
        if key not in self.stats:
            z = self.chunks[self.perm[0]] if self.perm[0] < len(self.chunks) else 1
            vals = [getattr(self[i:i + z].read(), name)() for i in range(0, self.shape[0], max(z, 1))]
            self.stats[key] = getattr(np.array(vals), name)()
        return self.stats[key]

    def min(self):
        return self._reduce("min")

    def max(self):
        return self._reduce("max")

    def astype(self, dtype, copy=True):
        return self.read().astype(dtype, copy=False)
