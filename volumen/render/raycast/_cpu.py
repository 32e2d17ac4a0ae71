"""CPU backend: pack the scene into a :class:`~._frame.Frame`, run the specialised kernel over tiles (Numba).

The driver (``_march.render_tiles``) runs 16x16-pixel tiles on every thread,
each thread taking the next tile when it finishes one (``volumen.jit.run_claiming``),
in a scrambled order, only those meeting the volume's projected footprint
(``_geometry.footprint``) traced and the others drawn blank after them (:func:`frame_tiles`); each pixel is one
call of ``_march.trace_pixel`` specialised for the frame's mode and shading model. ``pathtrace`` shading goes to the
progressive path tracer (:mod:`._progressive`).
"""

from __future__ import annotations

import time

import numpy as np

from ._frame import Outputs
from ._geometry import footprint
from ._march import render_tiles
from ._pack import pack_frame
from ._progressive import PathTracer
from ._tiles import TILE, frame_tiles, tile_order

__all__ = ["render_cpu", "render_part", "tile_order", "frame_tiles", "TILE", "frame_image"]


def frame_image(scene, f, out: Outputs, timings: dict, stats: dict, counts=None):
    """The :class:`~volumen.core.Image` of host outputs ``out`` of frame ``f`` (depth inf / value NaN where
    nothing was hit, as ``trace_pixel`` writes them); ``counts = (samples, hit rays)`` when the kernel counted
    them, else counted here."""
    from ...core import Image

    rgba, depth, value, nsamp = out
    w, h = f.size
    mode = scene.mode
    samples, hits = counts if counts is not None else (int(nsamp.sum(dtype=np.int64)), int(np.count_nonzero(nsamp)))
    stats = {"timings": timings, "samples": samples, "rays": w * h, "rays_hit": hits, "mode": mode,
             "shading": scene.shading.mode, "step_mm": f.ds, "reference_step_mm": f.ds0,
             "light_volumes_built": f.light_volumes_built, **stats}
    return Image(rgba=rgba, depth=depth, stats=stats, value=value if mode in ("mip", "minip", "average") else None)


def _draw(f, order, arrays=None, settings=None):
    """Run the tile kernel over ``order`` (:func:`frame_tiles`) into new outputs: ``(outputs, counts, seconds)``."""
    w, h = f.size
    out = Outputs.empty(w, h)
    t = time.perf_counter()
    counts = render_tiles(order, TILE, f.arrays if arrays is None else arrays,
                          f.settings if settings is None else settings, out, f.mode, f.light)
    return out, counts, time.perf_counter() - t


def render_cpu(scene, camera, size: tuple[int, int]):
    """Ray-cast ``scene`` seen by ``camera`` into an Image of ``size = (width, height)``; see
    ``volumen.render.render``."""
    if scene.shading.mode == "pathtrace" and scene.mode == "composite":
        return PathTracer(scene, camera, size).step(scene.shading.pathtrace.samples)
    t_start = time.perf_counter()
    f = pack_frame(scene, camera, size)
    w, h = f.size
    out, counts, kernel = _draw(f, frame_tiles(w, h, footprint(f.arrays.cam, f.arrays.geo)))
    timings = dict(f.timings, kernel=kernel, total=time.perf_counter() - t_start)
    return frame_image(scene, f, out, timings, {"backend": "cpu"}, counts)


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
    arrays = f.arrays._replace(whole=np.asarray(whole, np.float64), carry=np.asarray(carry, np.float32))
    traced = None if tiles is None else np.asarray(tiles, np.int64)  # indices, never read as a rectangle
    out, counts, kernel = _draw(f, frame_tiles(w, h, traced), arrays, f.settings._replace(part=True, stride=1))
    timings = dict(f.timings, kernel=kernel, total=time.perf_counter() - t_start)
    return frame_image(scene, f, out, timings, {"backend": "cpu"}, counts)
