"""Cache of per-volume precomputations, keyed by the Volume object.

A :class:`Prepared` is built the first time a volume is rendered and kept as
long as the Volume lives (weak keys). It is rebuilt when the Volume's
``data`` array object, shape, dtype or affine changes; call
:func:`clear_cache` after writing into ``volume.data`` in place.
"""

from __future__ import annotations

import threading
import time
import weakref

import numpy as np

from ...core import drawable_range, table_range
from ._color import NO_RGB, luminance_samples, rgb8
from ._normals import NO_CODES, NO_SLOTS, brick_codes, covers, encode_normals
from ._precompute import NLUT, build_blocks, int16_samples, normal_params

__all__ = ["Prepared", "prepare", "clear_cache", "prepared_volumes", "shared_table"]


class Prepared:
    """The samples of one volume as the kernels read them, and the lazily built normals and block grids.

    Attributes
    ----------
    u : (nz, ny, nx)
        The samples, int16 for every volume (``_precompute.int16_samples``): the volume's own data array when
        it is int16, C-contiguous and writable (no copy), else an int16 copy, shifted (integers) or quantized
        (floats). Either way ``(u - u0) * ufac`` maps ``[vmin, vmax]`` onto ``[0, NLUT - 1]``, the
        transfer-function table's index.
    u0, ufac : float
    vmin, vmax : float
        Value range (data units) the table spans: ``core.table_range`` (the data's, less the far outliers of an
        MRI whose few brightest voxels lie thousands of times past its tissue, clamped to ``vmax``, and a fill
        value far below the rest, clamped to ``vmin``). A brick of an out-of-core volume spans the whole
        volume's (``bricked.BrickVolume.value_range``).
    scale : float
        Data units per normalized unit.
    is_color, rgb
        A colour volume (``Volume.is_color``) is classified by its luminance: ``u`` holds
        ``_color.luminance_samples`` (8-bit channels: int16 fixed point, ``u0`` and ``ufac`` scaled to match),
        the value range is the luminance's in data units, and ``rgb`` holds its colours (``_color.rgb8``);
        a scalar volume has ``is_color = False`` and the placeholder ``_color.NO_RGB``.
    timings : dict
        Seconds spent building each part (only the parts built by the last call).
    """

    def __init__(self, volume, key):
        self.key = key
        t = time.perf_counter()
        self.is_color = bool(volume.is_color)
        self.rgb = rgb8(volume.data) if self.is_color else NO_RGB
        data, steps = luminance_samples(volume) if self.is_color else (volume.data, 1)
        full = (np.nanmin(data) / steps, np.nanmax(data) / steps) if self.is_color else volume.value_range()
        # a brick's table is the whole volume's (``bricked.BrickVolume``): its range as it is
        lo, hi = full if self.is_color or hasattr(volume, "whole_range") else table_range(volume, full)
        self.vmin, self.vmax = drawable_range(lo, hi)
        clamped = self.vmax < full[1] or self.vmin > full[0] or getattr(volume, "clamps", False)
        self.scale = (self.vmax - self.vmin) / (NLUT - 1)
        self.u, self.u0, self.ufac = int16_samples(data, self.vmin, self.vmax, steps, in_place=not clamped)
        self.u_copied = self.u is not data
        self.affine = np.array(volume.affine, dtype=float)
        self._normals: dict[tuple[bool, bool], tuple[np.ndarray, float]] = {}
        self._codes: dict[tuple[bool, bool, bool], tuple[np.ndarray, np.ndarray]] = {}
        self._blocks: dict[int, tuple[np.ndarray, np.ndarray]] = {}
        self._memo: dict = {}
        self.timings = {"normalize": time.perf_counter() - t}

    def to_u(self, value: float) -> float:
        """Data value -> normalized units (not clipped)."""
        return (float(value) - self.vmin) / self.scale

    def normals(self, sobel: bool, magnitude: bool = True) -> tuple[np.ndarray, float]:
        """``(normal parameters (4, 3) float64, gmax data units / mm)``; see :func:`normal_params` (without
        ``magnitude`` no pass over the volume, unless one was made before)."""
        if (sobel, True) in self._normals:
            return self._normals[sobel, True]
        if (sobel, magnitude) not in self._normals:
            t = time.perf_counter()
            self._normals[sobel, magnitude] = normal_params(self.u, self.affine, self.scale * self.ufac, sobel,
                                                            magnitude)
            self.timings["normals"] = time.perf_counter() - t
        return self._normals[sobel, magnitude]

    def codes(self, sobel: bool, directions: bool, magnitudes: bool, keep=None) -> tuple:
        """``(direction codes' pool, their bricks' slots, magnitude codes)`` (``_normals.brick_codes`` of the bricks
        ``keep``, None: every brick; ``_normals.encode_normals``' magnitudes); placeholders where not asked for. Only
        the last asked for are kept (a volume's codes are as large as its data), and built again where they lack a
        brick of ``keep`` or hold many more (``_normals.covers``)."""
        key = (sobel, directions, magnitudes)
        kept = self._codes.get(key)
        if kept is None or (directions and not covers(kept[0], keep)):
            nrm = self.normals(sobel, magnitudes)[0]  # 1 / gmax only for the magnitude codes
            self._codes = {}  # the old codes go before the new ones are built
            t = time.perf_counter()
            bricks = brick_codes(self.u, nrm, sobel, keep) if directions else None
            mags = encode_normals(self.u, nrm, sobel, directions=False, magnitudes=magnitudes)[1]
            self._codes = {key: (bricks, mags)}
            self.timings["normal codes"] = time.perf_counter() - t
        bricks, mags = self._codes[key]
        return (NO_CODES, NO_SLOTS, mags) if bricks is None else (bricks.pool, bricks.slots, mags)

    def memo(self, key, build):
        """``build()``, kept for the next frames asking with the same ``key`` (the last :data:`MEMO` kept):
        per-frame tables that depend on the volume and a few settings only, e.g. the skip distances of a
        transfer function, are not rebuilt while the user only moves the camera."""
        return _kept(self._memo, key, build)

    def memo_repeated(self, key, build, first, timing: str):
        """``first`` the first time ``key`` is asked for; from the second time on ``build()``, kept as
        :meth:`memo` keeps it (its seconds in ``timings[timing]``). For a table that pays for its pass over the
        volume only over several frames: while the user drags a transfer function each frame asks for a new
        key and gets ``first``; a camera move asks for the same one again."""
        if key not in self._memo:
            _kept(self._memo, key, lambda: _PENDING)
            return first
        if self._memo[key] is _PENDING:
            t = time.perf_counter()
            self._memo[key] = build()
            self.timings[timing] = time.perf_counter() - t
        return self._memo[key]

    def nbytes(self) -> int:
        """Bytes of the arrays built here (the int16 copy of the samples if one was made, colours, normals'
        codes, block grids, the memo's tables), not counting the volume's own data."""
        parts = [self.u if self.u_copied else None, self.rgb, list(self._codes.values()),
                 list(self._blocks.values()), list(self._memo.values())]
        return _nbytes(parts)

    def blocks(self, block: int) -> tuple[np.ndarray, np.ndarray]:
        """``(bmin, bmax)`` float32 block grids in normalized units; see :func:`build_blocks`."""
        if block not in self._blocks:
            t = time.perf_counter()
            bmin, bmax = build_blocks(self.u, block)
            if self.u0 != 0.0 or self.ufac != 1.0:  # in table units, in place a slab at a time (no grid-sized copy)
                for grid in (bmin, bmax):
                    for k in range(grid.shape[0]):
                        grid[k] = (grid[k] - self.u0) * self.ufac
            self._blocks[block] = bmin, bmax
            self.timings["blocks"] = time.perf_counter() - t
        return self._blocks[block]


#: what :meth:`Prepared.memo_repeated` keeps for a key asked for once
_PENDING = object()


def _nbytes(obj) -> int:
    """Bytes of the NumPy arrays in ``obj`` (arrays, tuples and lists of them, nested)."""
    if isinstance(obj, np.ndarray):
        return int(obj.nbytes)
    if isinstance(obj, (tuple, list)):
        return sum(_nbytes(o) for o in obj)
    return 0


#: per-frame tables kept per volume (:meth:`Prepared.memo`), and of every volume (:func:`shared_table`): a
#: composite transfer function keeps up to three per volume (skip distances, coarse blocks, cells)
MEMO = 12

_SHARED: dict = {}
_SHARED_LOCK = threading.Lock()


def shared_table(key, build):
    """``build()``, kept for whoever asks with the same ``key`` next (the last :data:`MEMO` kept): tables that
    depend on settings and a value range only, not on a volume's samples (the transfer function's colour
    table), shared by the volumes that ask for them -- the bricks of one out-of-core volume."""
    with _SHARED_LOCK:
        return _kept(_SHARED, key, build)


def _kept(store: dict, key, build):
    """``store[key]``, built by ``build()`` where missing; the oldest entry makes room beyond :data:`MEMO`."""
    if key not in store:
        if len(store) >= MEMO:
            store.pop(next(iter(store)))
        store[key] = build()
    return store[key]

_CACHE: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _key(volume) -> tuple:
    d = volume.data
    return (id(d), d.shape, d.dtype.str, np.asarray(volume.affine, float).tobytes())


def prepare(volume) -> Prepared:
    """The cached :class:`Prepared` of ``volume`` (built on first use)."""
    key = _key(volume)
    p = _CACHE.get(volume)
    if p is None or p.key != key:
        p = Prepared(volume, key)
        _CACHE[volume] = p
    else:
        p.timings = {}
    return p


def clear_cache(volume=None) -> None:
    """Forget the precomputations of ``volume`` (or of every volume, and the shared tables)."""
    if volume is None:
        _CACHE.clear()
        with _SHARED_LOCK:
            _SHARED.clear()
    else:
        _CACHE.pop(volume, None)


def prepared_volumes(volume=None) -> list:
    """The cached :class:`Prepared` of ``volume`` (empty list when none), or of every volume."""
    if volume is None:
        return list(_CACHE.values())
    p = _CACHE.get(volume)
    return [] if p is None else [p]
