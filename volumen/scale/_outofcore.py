"""Out-of-core ray casting: a chunked volume drawn brick by brick through a bounded chunk cache.

:func:`render_bricked` cuts the volume into bricks (:mod:`._bricks`), skips
those whose value range the transfer function maps to zero opacity (per-chunk
minima and maxima stored by the OME-Zarr writer; no chunk is read for them),
reads each remaining brick through a :class:`ChunkCache` bounded in bytes,
draws it with the in-memory ray caster on the whole volume's sample grid
(``volumen.render.raycast.render_part``: only the screen tiles the brick
covers), and composites the pictures front to back (:mod:`._composite`),
each ray starting a brick at the opacity the bricks in front accumulated. So
a ray stops where the whole ray stops (early termination), a brick behind
opaque pixels is neither read nor drawn, and the result equals the whole
volume drawn at once with the same scene (the tests: within 1e-5, composite
and MIP, default sampling).

While the user interacts, :func:`pick_level` chooses a coarse pyramid level
(about one voxel per pixel), and level 0 when idle.
"""

from __future__ import annotations

import time
from collections import OrderedDict
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from ..core import Image, is_chunked
from ..io import ChunkedArray, open_levels
from ..render.raycast import TILE, pack_geometry, render_part
from ._bricks import (
    brick_clipping,
    brick_grid,
    brick_scene,
    brick_visible,
    brick_volume,
    needs_gradients,
    screen_tiles,
    visibility_order,
)
from ._composite import MODES, Partial, add_carried, combine, empty_partial

__all__ = ["render_bricked", "draw_brick", "whole_geometry", "plan", "ChunkCache", "open_source", "pick_level",
           "parse_bytes"]


def parse_bytes(text) -> int:
    """``"4GB"``, ``"512MiB"``, ``"1.5e9"`` -> bytes."""
    if isinstance(text, (int, float)):
        return int(text)
    t = str(text).strip().upper().replace("IB", "B")
    for unit, f in (("TB", 1 << 40), ("GB", 1 << 30), ("MB", 1 << 20), ("KB", 1 << 10), ("B", 1)):
        if t.endswith(unit):
            return int(float(t[:-len(unit)]) * f)
    return int(float(t))


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


def open_source(source, level: int = 0) -> SimpleNamespace:
    """``(data, affine, spacing, cmin, cmax, chunk)`` of a path (OME-Zarr) or a Volume (chunked or in memory)."""
    if isinstance(source, (str, Path)):
        levels, _ = open_levels(source)
        lv = levels[level]
        return SimpleNamespace(data=lv.array, affine=lv.affine, spacing=lv.spacing, cmin=lv.cmin, cmax=lv.cmax,
                               chunk=lv.array.chunks[0], levels=levels)
    chunk = source.data.chunks[0] if is_chunked(source.data) else 64
    return SimpleNamespace(data=source.data, affine=np.asarray(source.affine), spacing=source.spacing, cmin=None,
                           cmax=None, chunk=chunk, levels=None, volume=source)


def pick_level(levels, size, interacting: bool) -> int:
    """Level 0 when idle; while interacting the finest level with at most about one voxel per pixel."""
    if not interacting or not levels:
        return 0
    target = max(size)
    for n, lv in enumerate(levels):
        if max(lv.shape) <= target:
            return n
    return len(levels) - 1


def _range_of(src, value_range):
    if value_range is not None:
        return value_range
    if src.cmin is not None:
        return float(np.min(src.cmin)), float(np.max(src.cmax))
    if getattr(src, "volume", None) is not None:
        return src.volume.value_range()
    return float(src.data.min()), float(src.data.max())


def _chunk_range(src, brick):
    """(min, max) over the chunks the brick reads, from the stored per-chunk ranges (None when not stored)."""
    if src.cmin is None:
        return None
    c = src.chunk
    sl = tuple(slice(a // c, (b - 1) // c + 1) for a, b in zip(brick.rlo, brick.rhi, strict=True))
    return float(src.cmin[sl].min()), float(src.cmax[sl].max())


def whole_geometry(src, scene) -> np.ndarray:
    """The whole volume's packed region (its box, the scene's clipping): the sample grid every brick follows."""
    return pack_geometry(SimpleNamespace(affine=src.affine, shape=tuple(src.data.shape)), scene.clipping)


def _occluded(carry, tiles, et: float) -> bool:
    """Whether every pixel of ``tiles`` already reached the early-termination opacity in front."""
    h, w = carry.shape
    ntx = -(-w // TILE)
    ys, xs = tiles // ntx, tiles % ntx
    rect = carry[ys.min() * TILE:(ys.max() + 1) * TILE, xs.min() * TILE:(xs.max() + 1) * TILE]
    return bool(rect.min() >= et)


def draw_brick(src, data, b, scene, camera, size, vr, whole, carry) -> Partial | None:
    """Brick ``b`` of ``data`` drawn on the whole volume's sample grid (``whole``), its rays starting at the
    opacity ``carry`` (H, W) in front (a full-size partial picture); None when it cannot show anything."""
    rng = _chunk_range(src, b)
    clip = brick_clipping(b, src.affine, scene.clipping)
    if clip is None or (rng is not None and not brick_visible(scene, *rng, vr)):
        return None
    tiles = screen_tiles(b, src.affine, camera, size, TILE)
    if tiles is not None and (tiles.size == 0 or _occluded(carry, tiles, scene.sampling.early_termination)):
        return None
    block = np.asarray(data[b.read_slices])
    if rng is None and not brick_visible(scene, float(block.min()), float(block.max()), vr):
        return None
    vol = brick_volume(b, block, src, vr)
    return Partial.of(render_part(brick_scene(scene, vol, clip), camera, size, whole, carry, tiles))


#: bricks of about this many voxels on a side by default: each brick costs a frame's packing and kernel launch
#: and reads one more voxel each side (neighbouring chunks), so bricks of one 64-voxel chunk cost about three
#: times the time of 128-voxel ones (``volumen bench scale``)
BRICK = 128


def default_brick(chunk: int) -> int:
    """The whole number of chunks closest to :data:`BRICK` voxels (one chunk at least)."""
    return int(chunk) * max(1, round(BRICK / int(chunk)))


def plan(source, scene, camera, *, level: int = 0, brick: int | None = None, value_range=None):
    """``(source info, value range, bricks front to back, brick edge)`` of a bricked drawing."""
    if scene.mode not in MODES:
        raise ValueError(f"bricked rendering draws modes {list(MODES)}, got {scene.mode!r}")
    if (scene.sampling.preintegrate or scene.shading.mode in ("shadows", "scattering", "pathtrace")
            or scene.transfer.gradient_opacity is not None):
        raise ValueError("bricked rendering draws post-classified samples lit by the headlight or phong (no "
                         "preintegrate, shadows, scattering or path tracing: they read beyond a brick; no gradient "
                         "opacity: its magnitudes are scaled by the whole volume's largest)")
    src = open_source(source, level)
    vr = _range_of(src, value_range)
    size_b = int(brick or default_brick(src.chunk))
    pad = 1 if needs_gradients(scene) else 0
    bricks = visibility_order(brick_grid(src.data.shape, size_b, pad), src.affine, size_b, camera)
    return src, vr, bricks


def _draw_all(src, data, bricks, scene, camera, size, vr):
    """The bricks drawn front to back and composited: ``(Partial, bricks drawn)``; composite carries each
    ray's opacity from brick to brick (:func:`~._composite.add_carried`), so rays stop where the whole ray
    stops and bricks hidden behind opaque pixels are neither read nor drawn."""
    w, h = size
    whole = whole_geometry(src, scene)
    acc, drawn = empty_partial(w, h), 0
    carried = scene.mode == "composite"
    zeros = np.zeros((h, w), np.float32)
    for b in bricks:
        carry = np.ascontiguousarray(acc.rgba[..., 3]) if carried else zeros
        part = draw_brick(src, data, b, scene, camera, size, vr, whole, carry)
        if part is not None:
            acc = add_carried(acc, part) if carried else combine(acc, part, scene.mode)
            drawn += 1
    return acc, drawn


def render_bricked(source, scene, camera, size=(512, 512), *, memory="4GB", level: int = 0, brick: int | None = None,
                   value_range=None, device: str | None = None) -> Image:
    """Draw ``scene`` (its own ``volume`` ignored) with the volume of ``source`` read brick by brick.

    Parameters
    ----------
    source : path of an OME-Zarr / Zarr image, or a Volume (chunked or in memory)
    scene : Scene
        Modes composite, mip, minip (sort-last operators of :mod:`._composite`); shading none, headlight or
        phong; no pre-integration, no gradient opacity.
    memory : bytes or str (``"4GB"``)
        Bound of the chunk cache.
    level : int
        Pyramid level (0: full resolution; :func:`pick_level`).
    brick : int, optional
        Cells per brick side (default: :func:`default_brick` of the chunk edge, about 128).
    device : None, "cpu" or "auto"
        Bricks are drawn on the CPU.

    Returns
    -------
    Image
        Equal (within float rounding) to the whole volume drawn at once with the same scene.
        ``stats``: ``bricks``, ``bricks_drawn``, ``bricks_skipped`` (empty, or hidden behind opaque
        pixels), ``chunk_reads`` (from the store), ``cache_peak_bytes``, ``timings``.
    """
    if device not in (None, "cpu", "auto"):
        raise ValueError(f"bricked rendering draws on the cpu, got device {device!r}")
    t0 = time.perf_counter()
    src, vr, bricks = plan(source, scene, camera, level=level, brick=brick, value_range=value_range)
    data, cache = src.data, None
    if is_chunked(data):
        cache = ChunkCache(data.source, parse_bytes(memory))
        data = ChunkedArray(cache, data.perm, data.start, data.step, data.shape)
    acc, drawn = _draw_all(src, data, bricks, scene, camera, tuple(int(s) for s in size), vr)
    stats = {"bricks": len(bricks), "bricks_drawn": drawn, "bricks_skipped": len(bricks) - drawn, "level": level,
             "chunk_reads": cache.misses if cache else 0, "cache_peak_bytes": cache.peak if cache else 0,
             "timings": {"total": time.perf_counter() - t0}, "mode": scene.mode}
    value = None if scene.mode == "composite" else acc.value
    return Image(rgba=acc.rgba, depth=acc.depth, stats=stats, value=value)
