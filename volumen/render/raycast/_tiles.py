"""The 16x16-pixel tiles of a picture, in a fixed scrambled order: the work the CPU drivers hand their threads
(the ray caster's ``_march.render_tiles`` through :func:`frame_tiles`, the path tracer's through
:func:`tile_order`)."""

from __future__ import annotations

import functools

import numpy as np

__all__ = ["TILE", "tile_order", "frame_tiles"]

TILE = 16


@functools.lru_cache(maxsize=16)
def _scrambled(n: int) -> np.ndarray:
    """A fixed permutation of ``range(n)`` (read-only: shared by every frame of that many tiles)."""
    order = np.random.default_rng(12345).permutation(n).astype(np.int64)
    order.flags.writeable = False
    return order


def tile_order(w: int, h: int, bounds=None) -> np.ndarray:
    """Scrambled (deterministic) order of the 16x16 tiles of a (w, h) picture; only those meeting the pixel
    rectangle ``bounds = (x0, y0, x1, y1)`` (x1, y1 exclusive) when given."""
    ntx, nty = (w + TILE - 1) // TILE, (h + TILE - 1) // TILE
    order = _scrambled(ntx * nty)
    if bounds is None:
        return order.copy()  # writable, as the kernels' array arguments always are (one compiled type)
    x0, y0, x1, y1 = bounds
    tx, ty = order % ntx, order // ntx
    keep = (tx * TILE < x1) & ((tx + 1) * TILE > x0) & (ty * TILE < y1) & ((ty + 1) * TILE > y0)
    return order[keep]


def frame_tiles(w: int, h: int, traced=None) -> np.ndarray:
    """The work of the tile kernel (``_march.render_tiles``) over a (w, h) picture: int64 rows ``(tile, run)``.

    First the traced tiles (``traced``: a pixel rectangle ``(x0, y0, x1, y1)``, x1, y1 exclusive, the tiles
    meeting it; or tile indices; None: all) in the scrambled order of :func:`tile_order`, ``run`` 0; then the
    others, drawn blank, as runs of ``run`` tiles along a tile row from tile index ``tile`` (cheap work last:
    it evens out the threads' ends, and a run is one claim, not one per tile).
    """
    ntx, nty = (w + TILE - 1) // TILE, (h + TILE - 1) // TILE
    first = tile_order(w, h, traced) if traced is None or isinstance(traced, tuple) else np.unique(traced)
    blank = np.ones((nty, ntx), bool)
    blank.flat[first] = False
    padded = np.pad(blank, ((0, 0), (1, 1))).astype(np.int8)
    edges = np.diff(padded, axis=1)  # +1 where a run starts, -1 one past its end
    ty, tx0 = np.nonzero(edges == 1)
    tx1 = np.nonzero(edges == -1)[1]
    runs = np.stack([ty * ntx + tx0, tx1 - tx0], axis=1)
    return np.concatenate([np.stack([first, np.zeros_like(first)], axis=1), runs]).astype(np.int64)
