"""CPU backend: pack the scene into a :class:`~._frame.Frame`, run the specialised kernel over tiles (Numba).

The driver (``_march.render_tiles``) runs 16x16-pixel tiles on every thread
taken in a scrambled order (so threads share the expensive middle of the
picture evenly), only those meeting the volume's projected footprint
(``_geometry.footprint``: the others stay cleared); each pixel is one call of ``_march.trace_pixel`` specialised
for the frame's mode and shading model. ``pathtrace`` shading goes to the
progressive path tracer (:mod:`._pathtrace`).
"""

from __future__ import annotations

import time

import numpy as np

from ._frame import FAR, Outputs
from ._geometry import footprint
from ._march import render_tiles
from ._pack import pack_frame

__all__ = ["render_cpu", "render_part", "tile_order", "TILE", "frame_image"]

TILE = 16


def tile_order(w: int, h: int, bounds=None) -> np.ndarray:
    """Scrambled (deterministic) order of the 16x16 tiles of a (w, h) picture; only those meeting the pixel
    rectangle ``bounds = (x0, y0, x1, y1)`` (x1, y1 exclusive) when given."""
    ntx, nty = (w + TILE - 1) // TILE, (h + TILE - 1) // TILE
    order = np.random.default_rng(12345).permutation(ntx * nty).astype(np.int64)
    if bounds is None:
        return order
    x0, y0, x1, y1 = bounds
    tx, ty = order % ntx, order // ntx
    keep = (tx * TILE < x1) & ((tx + 1) * TILE > x0) & (ty * TILE < y1) & ((ty + 1) * TILE > y0)
    return order[keep]


def frame_image(scene, f, out: Outputs, timings: dict, stats: dict, bounds=None):
    """The :class:`~volumen.core.Image` of host outputs ``out`` of frame ``f`` (FAR -> inf / NaN; only inside the
    pixel rectangle ``bounds = (x0, y0, x1, y1)`` when given: the rest was never traced)."""
    from ...core import Image

    rgba, depth, value, nsamp = out
    x0, y0, x1, y1 = bounds if bounds is not None else (0, 0, depth.shape[1], depth.shape[0])
    for a, gone in ((depth, np.inf), (value, np.nan)):
        sub = a[y0:y1, x0:x1]
        sub[sub >= 0.5 * FAR] = gone
    w, h = f.size
    mode = scene.mode
    stats = {"timings": timings, "samples": int(nsamp.sum(dtype=np.int64)), "rays": w * h,
             "rays_hit": int(np.count_nonzero(nsamp)), "mode": mode, "shading": scene.shading.mode,
             "step_mm": f.ds, "reference_step_mm": f.ds0, "light_volumes_built": f.light_volumes_built, **stats}
    return Image(rgba=rgba, depth=depth, stats=stats, value=value if mode in ("mip", "minip", "average") else None)


def _tiles_cover(bounds):
    """The pixel rectangle of the whole tiles meeting ``bounds`` (what the kernel traced)."""
    x0, y0, x1, y1 = bounds
    return (x0 // TILE) * TILE, (y0 // TILE) * TILE, -(-x1 // TILE) * TILE, -(-y1 // TILE) * TILE


def render_cpu(scene, camera, size: tuple[int, int]):
    """Ray-cast ``scene`` seen by ``camera`` into an Image of ``size = (width, height)``; see
    ``volumen.render.render``."""
    if scene.shading.mode == "pathtrace" and scene.mode == "composite":
        from ._pathtrace import PathTracer

        return PathTracer(scene, camera, size).step(scene.shading.pathtrace.samples)
    t_start = time.perf_counter()
    f = pack_frame(scene, camera, size)
    w, h = f.size
    out = Outputs.cleared(w, h)
    t = time.perf_counter()
    bounds = footprint(f.arrays.cam, f.arrays.geo)
    render_tiles(tile_order(w, h, bounds), TILE, f.arrays, f.settings, out, f.mode, f.light)
    timings = dict(f.timings, kernel=time.perf_counter() - t)
    timings["total"] = time.perf_counter() - t_start
    return frame_image(scene, f, out, timings, {"backend": "cpu"}, _tiles_cover(bounds))


def render_part(scene, camera, size: tuple[int, int], whole, carry: np.ndarray, tiles=None):
    """Draw ``scene`` (a part of a larger region: a brick) on the sample grid of the ``whole`` region, each
    ray starting at the opacity carried in (see ``_ray``); CPU only.

    Parameters
    ----------
    whole : (24,) float64
        The whole region's packed geometry (:func:`~._geometry.pack_geometry` of the whole volume and the
        scene's clipping): the rays sample its grid, and draw the samples inside ``scene``'s own region.
    carry : (H, W) float32
        Opacity accumulated in front of the part, per pixel (composite: a ray stops where the whole ray stops).
    tiles : int64 array, optional
        Indices of the 16x16 tiles to trace (row-major); the others are left empty (transparent, depth inf).

    Returns
    -------
    Image
        composite: ``rgba`` the part's colour seen through the opacity in front (add it to the colour in
        front) and alpha the opacity accumulated to the part's back side; other modes as ``render_cpu``.
    """
    t_start = time.perf_counter()
    f = pack_frame(scene, camera, size)
    w, h = f.size
    out = Outputs(np.zeros((h, w, 4), np.float32), np.full((h, w), FAR, np.float32),
                  np.full((h, w), FAR, np.float32), np.zeros((h, w), np.int32))
    arrays = f.arrays._replace(whole=np.asarray(whole, np.float64), carry=np.asarray(carry, np.float32))
    order = tile_order(w, h) if tiles is None else np.asarray(tiles, np.int64)
    t = time.perf_counter()
    render_tiles(order, TILE, arrays, f.settings._replace(part=True), out, f.mode, f.light)
    timings = dict(f.timings, kernel=time.perf_counter() - t, total=time.perf_counter() - t_start)
    return frame_image(scene, f, out, timings, {"backend": "cpu"})
