"""CPU backend: pack the scene into arrays, run ``trace_pixel`` over tiles in parallel (Numba).

The driver is a thin ``prange`` over 16x16-pixel tiles taken in a scrambled
order (so threads share the expensive middle of the picture evenly); each
pixel is one call of :func:`._trace.trace_pixel`. ``pathtrace`` shading goes
to the progressive path tracer (:mod:`._pathtrace`).
"""

from __future__ import annotations

import time

import numpy as np
from numba import njit, prange

from ._pack import pack_frame
from ._trace import FAR, trace_pixel

__all__ = ["render_cpu", "render_tiles", "tile_order", "TILE"]

TILE = 16


@njit(parallel=True, fastmath=True, cache=True)
def render_tiles(order, tile, cam, geo, planes, vol, nrm, lut, pre, glut, bflag, bmin, bmax, lights, lvm, lvd, sig,
                 prm, iprm, rgba, depth, value, nsamp):
    """Trace every pixel of ``rgba`` (H, W, 4), tile by tile in ``order`` (tile indices, row-major)."""
    h, w = depth.shape
    ntx = (w + tile - 1) // tile
    for n in prange(order.shape[0]):
        t = order[n]
        y0 = (t // ntx) * tile
        x0 = (t % ntx) * tile
        for py in range(y0, min(y0 + tile, h)):
            for px in range(x0, min(x0 + tile, w)):
                trace_pixel(px, py, cam, geo, planes, vol, nrm, lut, pre, glut, bflag, bmin, bmax, lights, lvm, lvd,
                            sig, prm, iprm, rgba, depth, value, nsamp)


def tile_order(w: int, h: int) -> np.ndarray:
    """Scrambled (deterministic) order of the 16x16 tiles of a (w, h) picture."""
    n = ((w + TILE - 1) // TILE) * ((h + TILE - 1) // TILE)
    return np.random.default_rng(12345).permutation(n).astype(np.int64)


def render_cpu(scene, camera, size: tuple[int, int]):
    """Ray-cast ``scene`` seen by ``camera`` into an Image of ``size = (width, height)``; see ``volumen.render.render``."""
    from ...core import Image

    if scene.shading.mode == "pathtrace" and scene.mode == "composite":
        from ._pathtrace import PathTracer

        return PathTracer(scene, camera, size).step(scene.shading.pt_samples)
    t_start = time.perf_counter()
    w, h = (int(s) for s in size)
    f = pack_frame(scene, camera, (w, h))
    timings = f.timings
    rgba = np.empty((h, w, 4), np.float32)
    depth = np.empty((h, w), np.float32)
    value = np.empty((h, w), np.float32)
    nsamp = np.empty((h, w), np.int32)
    t = time.perf_counter()
    render_tiles(tile_order(w, h), TILE, *f.args(), rgba, depth, value, nsamp)
    timings["kernel"] = time.perf_counter() - t
    depth[depth >= 0.5 * FAR] = np.inf
    value[value >= 0.5 * FAR] = np.nan
    timings["total"] = time.perf_counter() - t_start
    mode = scene.mode
    stats = {"timings": timings, "samples": int(nsamp.sum(dtype=np.int64)), "rays": w * h,
             "rays_hit": int(np.count_nonzero(nsamp)), "backend": "cpu", "mode": mode,
             "shading": scene.shading.mode, "step_mm": f.ds, "reference_step_mm": f.ds0,
             "light_volumes_built": f.light_volumes_built}
    return Image(rgba=rgba, depth=depth, stats=stats,
                 value=value if mode in ("mip", "minip", "average") else None)
