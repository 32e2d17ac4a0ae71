"""CPU backend: pack the scene into arrays, run ``trace_pixel`` over tiles in parallel (Numba).

The driver is a thin ``prange`` over 16x16-pixel tiles taken in a scrambled
order (so threads share the expensive middle of the picture evenly); each
pixel is one call of :func:`._trace.trace_pixel`.
"""

from __future__ import annotations

import time

import numpy as np
from numba import njit, prange

from ._cache import prepare
from ._geometry import pack_camera, pack_geometry, pack_planes
from ._precompute import NLUT
from ._shade import headlight, pack_lights
from ._tables import (NPRE, block_visibility, color_table, gradient_table, iso_visibility, preintegrated_table,
                      skip_distance)
from ._trace import (I_SHADED, I_BLOCK, I_GRADOP, I_JITTER, I_MODE, I_NEAREST, I_NLIGHTS, I_NPLANES, I_PREINT, I_SEED,
                     I_SKIP, MODE_CODES, N_IPRM, N_PRM, P_DS, P_ET, P_ISO, P_ISO_R, P_KA, P_KD, P_KS,
                     P_PRE_SCALE, P_SHINE, P_VMIN, P_VSCALE, FAR, trace_pixel)

__all__ = ["render_cpu", "TILE"]

TILE = 16


@njit(parallel=True, fastmath=True, cache=True)
def render_tiles(order, tile, cam, geo, planes, vol, nrm, lut, pre, glut, bflag, bmin, bmax, lights, prm, iprm,
                 rgba, depth, value, nsamp):
    """Trace every pixel of ``rgba`` (H, W, 4), tile by tile in ``order`` (tile indices, row-major)."""
    h, w = depth.shape
    ntx = (w + tile - 1) // tile
    for n in prange(order.shape[0]):
        t = order[n]
        y0 = (t // ntx) * tile
        x0 = (t % ntx) * tile
        for py in range(y0, min(y0 + tile, h)):
            for px in range(x0, min(x0 + tile, w)):
                trace_pixel(px, py, cam, geo, planes, vol, nrm, lut, pre, glut, bflag, bmin, bmax, lights, prm,
                            iprm, rgba, depth, value, nsamp)


def _tile_order(w: int, h: int) -> np.ndarray:
    n = ((w + TILE - 1) // TILE) * ((h + TILE - 1) // TILE)
    return np.random.default_rng(12345).permutation(n).astype(np.int64)


def render_cpu(scene, camera, size: tuple[int, int]):
    """Ray-cast ``scene`` seen by ``camera`` into an Image of ``size = (width, height)``; see ``volumen.render.render``."""
    from ...core import Image

    t_start = time.perf_counter()
    volume = scene.volume
    w, h = (int(s) for s in size)
    prep = prepare(volume)
    timings = dict(prep.timings)
    smp = scene.sampling
    mode = scene.mode
    code = MODE_CODES[mode]
    tf = scene.transfer
    ds0 = float(min(volume.spacing))
    ds = ds0 / smp.samples_per_voxel
    ratio = ds / ds0

    t = time.perf_counter()
    preint = smp.preintegrate and mode == "composite"
    lut = color_table(tf, prep.vmin, prep.vmax, ratio if (mode == "composite" and not preint) else None)
    pre = preintegrated_table(tf, prep.vmin, prep.vmax, ratio) if preint else np.zeros((1, 1, 4), np.float32)
    shaded = scene.shading.mode != "none" and mode in ("composite", "isosurface")
    gradop = tf.gradient_opacity is not None and mode == "composite"
    if shaded or gradop:
        nrm, gmax = prep.normals(scene.shading.gradient == "sobel")
    else:
        nrm, gmax = np.zeros((1, 1, 1, 4), np.int16), 0.0
    glut = gradient_table(tf, gmax) if gradop else np.ones(128, np.float32)
    u_iso = prep.to_u(scene.isosurface.value)
    skip = smp.skip_empty and mode != "average"
    if skip:
        bmin, bmax = prep.blocks(smp.block_size)
        if mode == "composite":
            bflag = skip_distance(block_visibility(lut[:, 3], bmin, bmax))
        elif mode == "isosurface":
            bflag = skip_distance(iso_visibility(u_iso, bmin, bmax))
        else:  # mip / minip decide per ray from bmin / bmax
            bflag = np.zeros(bmin.shape, np.uint8)
    else:
        bmin = bmax = np.zeros((1, 1, 1), np.float32)
        bflag = np.zeros((1, 1, 1), np.uint8)
    timings.update(prep.timings)
    timings["tables"] = time.perf_counter() - t

    if not shaded:
        lights = np.zeros((1, 10), np.float64)
        nlights = 0
    elif scene.shading.mode == "headlight":
        lights, nlights = headlight(camera), 1
    else:
        lights, nlights = pack_lights(scene.lights), len(scene.lights)
    sh = scene.shading
    prm = np.zeros(N_PRM, np.float64)
    prm[P_DS], prm[P_ET] = ds, smp.early_termination
    prm[P_KA], prm[P_KD], prm[P_KS], prm[P_SHINE] = sh.ambient, sh.diffuse, sh.specular, sh.shininess
    prm[P_VMIN], prm[P_VSCALE] = prep.vmin, prep.scale
    prm[P_ISO] = u_iso
    prm[P_ISO_R:P_ISO_R + 3] = scene.isosurface.color
    prm[P_PRE_SCALE] = (NPRE - 1) / (NLUT - 1)
    iprm = np.zeros(N_IPRM, np.int64)
    iprm[I_MODE], iprm[I_NEAREST] = code, int(smp.interpolation == "nearest")
    iprm[I_JITTER], iprm[I_SEED] = int(smp.jitter), smp.seed
    iprm[I_SKIP], iprm[I_BLOCK], iprm[I_PREINT] = int(skip), smp.block_size, int(preint)
    iprm[I_NLIGHTS], iprm[I_GRADOP] = nlights, int(gradop)
    iprm[I_NPLANES] = len(scene.clipping.planes)
    iprm[I_SHADED] = int(shaded)

    rgba = np.empty((h, w, 4), np.float32)
    depth = np.empty((h, w), np.float32)
    value = np.empty((h, w), np.float32)
    nsamp = np.empty((h, w), np.int32)
    t = time.perf_counter()
    render_tiles(_tile_order(w, h), TILE, pack_camera(camera, (w, h)), pack_geometry(volume, scene.clipping),
                 pack_planes(scene.clipping), prep.u, nrm, lut, pre, glut, bflag, bmin, bmax, lights, prm, iprm,
                 rgba, depth, value, nsamp)
    timings["kernel"] = time.perf_counter() - t
    depth[depth >= 0.5 * FAR] = np.inf
    value[value >= 0.5 * FAR] = np.nan
    timings["total"] = time.perf_counter() - t_start
    stats = {"timings": timings, "samples": int(nsamp.sum(dtype=np.int64)), "rays": w * h,
             "rays_hit": int(np.count_nonzero(nsamp)), "backend": "cpu", "mode": mode,
             "step_mm": ds, "reference_step_mm": ds0}
    return Image(rgba=rgba, depth=depth, stats=stats,
                 value=value if mode in ("mip", "minip", "average") else None)
