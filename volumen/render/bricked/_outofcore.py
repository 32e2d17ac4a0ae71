"""Out-of-core ray casting: a chunked volume drawn brick by brick through a bounded chunk cache.

:func:`render_bricked` (what ``volumen.render`` does with a chunked volume)
cuts the volume into bricks (:mod:`._bricks`), skips those whose value range
the transfer function maps to zero opacity (the per-chunk minima and maxima
the OME-Zarr writer stored, which the chunked array answers: no chunk is read
for them), reads each remaining brick through the array's chunk cache bounded
in bytes (``data.cached(max_bytes)``: the chunked-array protocol of
:func:`volumen.core.is_chunked`; ``volumen.io`` implements it), draws it with
the in-memory ray caster on the whole volume's sample grid
(``volumen.render.raycast.render_part``: only the screen tiles the brick
covers), and composites the pictures front to back (:mod:`._composite`),
each ray starting a brick at the opacity the bricks in front accumulated. So
a ray stops where the whole ray stops (early termination), a brick behind
opaque pixels is neither read nor drawn, and the result equals the whole
volume drawn at once with the same scene (the tests: within 1e-5, composite
and MIP, default sampling). Nothing here opens a file: the volume's data
reads its own chunks (opening OME-Zarr paths and pyramid levels is
``volumen.scale``'s).
"""

from __future__ import annotations

import time
from types import SimpleNamespace

import numpy as np

from ...core import Image, is_chunked, table_range
from ..raycast import TILE, pack_geometry, prepared_volumes, render_part, scene_lights
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

__all__ = ["render_bricked", "draw_brick", "whole_geometry", "plan", "source_of", "chunk_range", "parse_bytes",
           "default_brick", "BRICK", "ROOM", "MEMORY"]

#: default bound of the chunk cache (bytes)
MEMORY = 4 << 30


def parse_bytes(text) -> int:
    """``"4GB"``, ``"512MiB"``, ``"1.5e9"`` -> bytes."""
    if isinstance(text, (int, float)):
        return int(text)
    t = str(text).strip().upper().replace("IB", "B")
    for unit, f in (("TB", 1 << 40), ("GB", 1 << 30), ("MB", 1 << 20), ("KB", 1 << 10), ("B", 1)):
        if t.endswith(unit):
            return int(float(t[:-len(unit)]) * f)
    return int(float(t))


def source_of(volume) -> SimpleNamespace:
    """``(data, affine, spacing, cmin, cmax, chunk, volume)`` of a Volume (chunked or in memory): ``cmin`` /
    ``cmax`` the per-chunk value ranges its chunked data answers (None when not stored), ``chunk`` the chunk
    edge (voxels; 64 for data in memory)."""
    data = volume.data
    ranges = getattr(data, "chunk_ranges", None) if is_chunked(data) else None
    cmin, cmax = ranges if ranges is not None else (None, None)
    chunk = data.chunks[0] if is_chunked(data) else 64
    return SimpleNamespace(data=data, affine=np.asarray(volume.affine), spacing=volume.spacing, cmin=cmin,
                           cmax=cmax, chunk=chunk, volume=volume)


def chunk_range(src, brick):
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
    y0, y1, x0, x1 = _rect(tiles, carry.shape[::-1])
    return bool(carry[y0:y1, x0:x1].min() >= et)


def _brick_volume(src, data, b, vr, cache, rng):
    """Brick ``b``'s :class:`~._bricks.BrickVolume`, from ``cache``'s derived entries (with the ray caster's
    precomputations for it: normal codes, skip blocks, tables) or read from ``data`` (its chunks); ``rng`` its
    stored chunk ranges (None: none stored, its block's own range is read)."""
    key = ("brick", b.rlo, b.rhi, float(vr[0]), float(vr[1]))
    vol = cache.derived(key) if cache is not None else None
    if vol is None:
        block = np.asarray(data[b.read_slices])
        own = rng if rng is not None else (float(block.min()), float(block.max()))
        vol = brick_volume(b, block, src, vr, clamps=own[0] < vr[0] or own[1] > vr[1])
        vol.block_range = own if rng is None else None
    return key, vol


def _keep(cache, key, vol) -> None:
    """Keep the brick's volume, its samples and the ray caster's precomputations for it under the cache's bound."""
    if cache is not None:
        cache.keep(key, vol, vol.data.nbytes + sum(p.nbytes() for p in prepared_volumes(vol)))


#: what a brick's drawing built (a Prepared's ``timings`` keys) -> the counter of ``render_bricked``'s stats
BUILT = {"normalize": "bricks_prepared", "normal codes": "normals_encoded", "blocks": "skip_blocks_built"}


def draw_brick(src, data, b, scene, camera, size, vr, whole, carry, *, cache=None, tally=None) -> Partial | None:
    """Brick ``b`` of ``data`` drawn on the whole volume's sample grid (``whole``), its rays starting at the
    opacity ``carry`` (H, W) in front (a full-size partial picture); None when it cannot show anything.

    ``cache`` (the chunk cache ``data`` reads through, or None): the brick's volume and what the ray caster
    derives from it are kept there, counted against its bound, and found again the next frames. ``tally``
    (a dict) counts what was built (:data:`BUILT`)."""
    rng = chunk_range(src, b)
    clip = brick_clipping(b, src.affine, scene.clipping)
    if clip is None or (rng is not None and not brick_visible(scene, *rng, vr)):
        return None
    tiles = screen_tiles(b, src.affine, camera, size, TILE)
    if tiles is not None and (tiles.size == 0 or _occluded(carry, tiles, scene.sampling.early_termination)):
        return None
    key, vol = _brick_volume(src, data, b, vr, cache, rng)
    if rng is None and not brick_visible(scene, *vol.block_range, vr):
        _keep(cache, key, vol)
        return None
    image = render_part(brick_scene(scene, vol, clip), camera, size, whole, carry, tiles)
    _keep(cache, key, vol)
    if tally is not None:
        for name, counter in BUILT.items():
            tally[counter] = tally.get(counter, 0) + (name in image.stats["timings"])
    return Partial.of(image, None if tiles is None else _rect(tiles, size))


def _rect(tiles, size) -> tuple[int, int, int, int]:
    """``(y0, y1, x0, x1)``: the pixels of the bounding box of ``tiles`` (row-major indices) in a ``size``
    picture."""
    ntx = -(-int(size[0]) // TILE)
    ys, xs = tiles // ntx, tiles % ntx
    return int(ys.min()) * TILE, (int(ys.max()) + 1) * TILE, int(xs.min()) * TILE, (int(xs.max()) + 1) * TILE


#: bricks of about this many voxels on a side by default: each brick costs a frame's packing and kernel launch
#: and reads one more voxel each side (neighbouring chunks), so bricks of one 64-voxel chunk cost about three
#: times the time of 128-voxel ones (``volumen bench scale``)
BRICK = 128
#: a cache of at least this many times the volume's bytes holds its chunks and what every brick derives
#: (samples, normal codes, skip blocks): bricks twice :data:`BRICK` then (at 488x404x448 int16, 8 bricks
#: instead of 64: warm frames 1.2x the in-memory time instead of 2.1x)
ROOM = 4


def default_brick(chunk: int, room: bool = False) -> int:
    """The whole number of chunks closest to :data:`BRICK` voxels, twice that with ``room`` (a cache of
    :data:`ROOM` times the volume; one chunk at least)."""
    return int(chunk) * max(1, round(BRICK * (2 if room else 1) / int(chunk)))


def plan(volume, scene, camera, *, brick: int | None = None, value_range=None):
    """``(source info, value range, bricks front to back)`` of a bricked drawing of ``volume``."""
    if scene.mode not in MODES:
        raise ValueError(f"bricked rendering draws modes {list(MODES)}, got {scene.mode!r}")
    if (scene.sampling.preintegrate or scene.shading.mode in ("shadows", "scattering", "pathtrace")
            or scene.transfer.gradient_opacity is not None):
        raise ValueError("bricked rendering draws post-classified samples lit by the headlight or phong (no "
                         "preintegrate, shadows, scattering or path tracing: they read beyond a brick; no gradient "
                         "opacity: its magnitudes are scaled by the whole volume's largest)")
    src = source_of(volume)
    # over the data range (given, else ``Volume.value_range``: a chunked volume's from its stored chunk ranges), the
    # table's (its sample planes read once: ``strided_values``)
    vr = table_range(src.volume, value_range)
    size_b = int(brick or default_brick(src.chunk))
    pad = 1 if needs_gradients(scene) else 0
    bricks = visibility_order(brick_grid(src.data.shape, size_b, pad), src.affine, size_b, camera)
    return src, vr, bricks


def whole_rig(scene, camera):
    """The scene with the studio rig's lights (its lights when it has none, lit by the studio environment) placed
    for the whole volume: each brick, a Volume of its own, would place them about its own centre."""
    if scene.lights:
        return scene
    lights = scene_lights(scene, camera)  # the rig, placed about the whole volume (or none)
    return scene.with_(lights=lights, environment=scene.environment.resolved(False)) if lights else scene


def _draw_all(src, data, bricks, scene, camera, size, vr, cache, tally):
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
        part = draw_brick(src, data, b, scene, camera, size, vr, whole, carry, cache=cache, tally=tally)
        if part is not None:
            acc = add_carried(acc, part) if carried else combine(acc, part, scene.mode)
            drawn += 1
    return acc, drawn


def render_bricked(scene, camera, size=(512, 512), *, memory=MEMORY, brick: int | None = None, value_range=None,
                   device: str | None = None) -> Image:
    """Draw ``scene`` with its ``volume`` (chunked, or in memory) read brick by brick.

    Parameters
    ----------
    scene : Scene
        Modes composite, mip, minip (sort-last operators of :mod:`._composite`); shading none, headlight or
        phong; no pre-integration, no gradient opacity.
    camera : Camera
    size : (width, height), pixels
    memory : bytes or str (``"4GB"``)
        Bound of the chunk cache (a chunked volume).
    brick : int, optional
        Cells per brick side (default: :func:`default_brick` of the chunk edge, about 128; about 256 when
        ``memory`` is :data:`ROOM` times the volume's bytes or more).
    value_range : (float, float), optional
        The whole volume's value range (default: the stored per-chunk ranges, else ``volume.value_range()``);
        the bricks' tables span its ``core.table_range`` (a fill far below cut off: the values past it clamped).
    device : None, "cpu" or "auto"
        Bricks are drawn on the CPU.

    Returns
    -------
    Image
        Equal (within float rounding) to the whole volume drawn at once with the same scene.
        ``stats``: ``bricks``, ``brick`` (cells a side), ``bricks_drawn``, ``bricks_skipped`` (empty, or
        hidden behind opaque pixels), ``chunk_reads`` (read from the store and decoded this frame), ``bricks_prepared``,
        ``normals_encoded``, ``skip_blocks_built`` (bricks whose samples, normal codes, skip blocks the ray
        caster prepared this frame: none for a brick found in the cache), ``cache_bytes``,
        ``cache_peak_bytes``, ``level`` (the volume's pyramid level), ``timings`` (seconds).
    """
    if device not in (None, "cpu", "auto"):
        raise ValueError(f"bricked rendering draws on the cpu, got device {device!r}")
    t0 = time.perf_counter()
    data = scene.volume.data
    if brick is None and is_chunked(data):
        brick = default_brick(data.chunks[0], room=ROOM * data.nbytes <= parse_bytes(memory))
    scene = whole_rig(scene, camera)
    src, vr, bricks = plan(scene.volume, scene, camera, brick=brick, value_range=value_range)
    data, cache = src.data, None
    if is_chunked(data):
        data, cache = data.cached(parse_bytes(memory))
        cache.new_frame()
    misses, tally = cache.misses if cache else 0, dict.fromkeys(BUILT.values(), 0)
    acc, drawn = _draw_all(src, data, bricks, scene, camera, tuple(int(s) for s in size), vr, cache, tally)
    stats = {"bricks": len(bricks), "brick": int(brick or default_brick(src.chunk)), "bricks_drawn": drawn,
             "bricks_skipped": len(bricks) - drawn,
             "level": int(scene.volume.meta.get("level", 0)), "chunk_reads": cache.misses - misses if cache else 0,
             "cache_peak_bytes": cache.peak if cache else 0, "cache_bytes": cache.bytes if cache else 0, **tally,
             "timings": {"total": time.perf_counter() - t0}, "mode": scene.mode}
    value = None if scene.mode == "composite" else acc.value
    return Image(rgba=acc.rgba, depth=acc.depth, stats=stats, value=value)
