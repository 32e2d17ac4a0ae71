"""Compiled first-hit marching through a wall field: the kernels behind collisions and the unfolded view.

A *wall field* is a scalar array ``field[z, y, x]`` with a ``level``: the wall
is where the trilinear interpolation of ``field`` is ``>= level``, the lumen
where it is below (see :class:`volumen.endoscopy.WallField`). Rays are given in
world RAS+ mm (``p(t) = o + t d``, ``d`` unit, ``t`` in mm) and converted to
voxel-index space through the packed geometry of the renderer
(``volumen.render.raycast._geometry.pack_geometry``); samples come from the
renderer's trilinear reconstruction (``_sample.sample_value``) and a crossing
between the two samples around it is located by the renderer's regula falsi
(``_trace.iso_refine``), so no reconstruction formula is written twice.

The kernels take the wall as one record, :class:`Wall` (field, packed geometry,
level, marching step), and points and directions as ``(x, y, z)`` tuples;
every function is ``@njit(cache=True)``.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ...jit import njit

# The renderer's sampling and crossing refinement, imported (not copied) as docs/design.md section 4 asks.
from ...render.raycast import G_BOX, G_INV, iso_refine, sample_value, to_index

__all__ = ["NO_HIT", "Wall", "first_hit", "wall_gradient", "probe", "fibonacci_directions"]

#: returned by :func:`first_hit` when no wall lies within the asked length
NO_HIT = 1e30


class Wall(NamedTuple):
    """A wall field as the kernels take it (Numba compiles it as a struct)."""

    field: np.ndarray  #: samples [z, y, x]; the wall is where their trilinear interpolation is >= level
    geo: np.ndarray    #: packed float64 geometry (world -> index affine, index box)
    level: float       #: wall threshold, field units
    step: float        #: marching step, mm


def fibonacci_directions(n: int) -> np.ndarray:
    """``n`` unit vectors spread evenly over the sphere (Fibonacci lattice), float64 (n, 3)."""
    k = np.arange(n, dtype=float) + 0.5
    z = 1.0 - 2.0 * k / n
    phi = np.pi * (1.0 + np.sqrt(5.0)) * k
    r = np.sqrt(np.maximum(1.0 - z * z, 0.0))
    return np.ascontiguousarray(np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1))


@njit(cache=True)
def _inside_box(geo, i, j, k):
    return (geo[G_BOX] <= i <= geo[G_BOX + 3] and geo[G_BOX + 1] <= j <= geo[G_BOX + 4]
            and geo[G_BOX + 2] <= k <= geo[G_BOX + 5])


@njit(cache=True)
def first_hit(w, o, d, tmax):
    """Distance (mm) along the ray ``o + t d`` (tuples, world mm, ``d`` unit) to the first point of the wall ``w``.

    The ray is sampled every ``w.step`` mm from ``t = 0`` up to ``tmax``; the
    crossing between the last sample below the level and the first at or
    above it is refined by regula falsi on the trilinear field. Leaving the
    volume's box of voxel centres counts as a hit at the last sample inside.
    Returns 0 when the origin is already in the wall, :data:`NO_HIT` when
    nothing is met within ``tmax``.
    """
    field, geo, level, step = w.field, w.geo, w.level, w.step
    oi, oj, ok = to_index(geo, o[0], o[1], o[2], 1.0)
    di, dj, dk = to_index(geo, d[0], d[1], d[2], 0.0)
    if not _inside_box(geo, oi, oj, ok):
        return 0.0
    vp = sample_value(field, oi, oj, ok, False)
    if vp >= level:
        return 0.0
    tp = 0.0
    while tp < tmax:
        t = min(tp + step, tmax)
        i = oi + t * di
        j = oj + t * dj
        k = ok + t * dk
        if not _inside_box(geo, i, j, k):
            return tp
        v = sample_value(field, i, j, k, False)
        if v >= level:
            return iso_refine(field, False, level, (tp, vp), (t, v), (oi, oj, ok), (di, dj, dk))
        tp = t
        vp = v
    return NO_HIT


@njit(cache=True)
def wall_gradient(w, p):
    """World-space gradient (field units per mm) of the wall's trilinear field at the world point ``p`` (tuple).

    Central differences of half a voxel in index space, mapped to world space
    through the transpose of the inverse affine (``geo[G_INV:G_INV + 12]``, rows of the
    world -> index matrix). Points into the wall (toward larger values).
    """
    field, geo = w.field, w.geo
    i, j, k = to_index(geo, p[0], p[1], p[2], 1.0)
    h = 0.5
    gi = (sample_value(field, i + h, j, k, False) - sample_value(field, i - h, j, k, False)) / (2 * h)
    gj = (sample_value(field, i, j + h, k, False) - sample_value(field, i, j - h, k, False)) / (2 * h)
    gk = (sample_value(field, i, j, k + h, False) - sample_value(field, i, j, k - h, False)) / (2 * h)
    gx = geo[G_INV] * gi + geo[G_INV + 4] * gj + geo[G_INV + 8] * gk
    gy = geo[G_INV + 1] * gi + geo[G_INV + 5] * gj + geo[G_INV + 9] * gk
    gz = geo[G_INV + 2] * gi + geo[G_INV + 6] * gj + geo[G_INV + 10] * gk
    return gx, gy, gz


@njit(cache=True)
def probe(w, p, dirs, radius):
    """Nearest wall seen from ``p`` (tuple, world mm) along the probe directions ``dirs`` (n, 3), within ``radius`` mm.

    Returns ``(t, k)``: the smallest hit distance (mm, :data:`NO_HIT` if none)
    and the index of its direction (-1 if none). With directions spread
    evenly (largest angle ``a`` to the nearest one) ``t`` overestimates the
    distance to a flat wall by at most the factor ``1 / cos(a)``.
    """
    best = NO_HIT
    kbest = -1
    for n in range(dirs.shape[0]):
        t = first_hit(w, p, (dirs[n, 0], dirs[n, 1], dirs[n, 2]), min(radius, best))
        if t < best:
            best = t
            kbest = n
            if t == 0.0:
                break
    return best, kbest
