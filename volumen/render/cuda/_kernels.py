"""The CUDA kernels: thin grid drivers, one thread per pixel (or per lattice ray), around the shared functions.

Each kernel is the CUDA twin of a CPU driver (run on the CPU's threads by ``volumen.jit``) and calls the same
per-pixel / per-ray function (see :mod:`._target`):

* :func:`trace`: ``raycast.trace_pixel`` for pixel ``(px, py)``, specialised (like the CPU driver) for the
  frame's mode and light tags;
* :func:`paths`: ``raycast.trace_path`` for samples ``s0 .. s1 - 1`` of a pixel (and, from sample 0, its
  opacity: ``raycast.coverage_pixel``);
* :func:`sweep`: one lattice ray of an illumination volume swept slice by slice with
  ``raycast.lattice_step``.

Kernels take the frame's records (``raycast.Arrays``, ``raycast.Settings``,
``raycast.Outputs``) whole; numba passes a tuple argument to a kernel field by field.

This module imports numba's CUDA target: the other modules of the package
import it inside the functions that launch kernels. The kernels compile on
their first launch with each set of argument types.
"""

from __future__ import annotations

import warnings

from numba import cuda

from ..raycast import (
    LatticeRay,
    coverage_pixel,
    for_cuda,
    lattice_frame,
    lattice_ray,
    lattice_slice,
    lattice_step,
    lattice_transmittance_of,
    sweep_medium,
    trace_path,
    trace_pixel,
)
from ._device import simulator
from ._target import device_function

__all__ = ["trace", "paths", "sweep", "grid_2d", "BLOCK_2D"]

#: threads per block of the 2-D grids (x, y)
BLOCK_2D = (16, 8)

if not simulator():
    for_cuda()  # the mode and light pieces, inlined as on the CPU (raycast._pieces.for_cuda)
    # a small picture (a thumbnail, a slab's preview) is a grid of few blocks: numba-cuda warns of low occupancy
    from numba.cuda.core.errors import NumbaPerformanceWarning

    warnings.filterwarnings("ignore", message=r".*Grid size \d+ will likely result in GPU under-utilization",
                            category=NumbaPerformanceWarning)

_trace_pixel = device_function(trace_pixel)
_trace_path = device_function(trace_path)
_coverage = device_function(coverage_pixel)
_frame = device_function(lattice_frame)
_ray = device_function(lattice_ray)
_slice = device_function(lattice_slice)
_step = device_function(lattice_step)
_transmittance = device_function(lattice_transmittance_of)
_medium = device_function(sweep_medium)


@cuda.jit(fastmath=True)
def trace(a, s, out, mode, light):
    """One thread per pixel of ``out.depth`` (H, W): ``trace_pixel``."""
    px, py = cuda.grid(2)
    if px < out.depth.shape[1] and py < out.depth.shape[0]:
        _trace_pixel(px, py, a, s, out, mode, light)


@cuda.jit(fastmath=True)
def paths(s0, s1, a, s, acc, alpha, feat):
    """One thread per pixel of ``acc`` (H, W, NACC): ``trace_path`` for samples ``s0 .. s1 - 1``; from sample 0 the
    pixel's opacity into ``alpha`` (H, W) and its denoiser features into ``feat`` (H, W, NFEAT)."""
    px, py = cuda.grid(2)
    if px < acc.shape[1] and py < acc.shape[0]:
        if s0 == 0:
            _coverage(px, py, a, s, alpha, feat)
        for k in range(s0, s1):
            _trace_path(px, py, k, a, s, acc)


@cuda.jit(fastmath=True)
def sweep(sw, out):
    """One thread per lattice ray ``(v, u)`` of ``out`` (nk, nv, nu), swept over its slices nearest-first;
    ``sw`` is a ``raycast.Sweep``."""
    u, v = cuda.grid(2)
    if u < out.shape[2] and v < out.shape[1]:
        pa, pb, pc, da, k0, nk, dsl, fwd = _frame(sw.meta)
        db, dc, t0, t1, length, sub = _ray(sw.aff, sw.geo, sw.planes, sw.nplanes, sw.meta, v, u)
        scale = sw.extinction_scale / sw.ds0
        acc = 0.0
        sp = -1.0
        for st in range(nk):
            i, k, s = _slice(st, nk, k0, pa, dsl, fwd)
            acc, sp = _step(_medium(sw), k, s, dsl, LatticeRay(pa, pb, pc, da, db, dc, t0, t1, length, sub), acc, sp)
            out[i, v, u] = _transmittance(acc, scale)


def grid_2d(w: int, h: int) -> tuple[tuple[int, int], tuple[int, int]]:
    """``(blocks, threads)`` covering a (w, h) grid with :data:`BLOCK_2D` blocks."""
    bx, by = BLOCK_2D
    return ((w + bx - 1) // bx, (h + by - 1) // by), BLOCK_2D
