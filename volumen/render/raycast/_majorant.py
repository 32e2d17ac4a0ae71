"""Free-flight sampling and transmittance through a majorant grid: delta and ratio tracking per block.

The path tracer's medium (``_medium.depth_at``: extinction ``sigma_t = kext * tau / ds0``) is bounded per block
of ``B^3`` voxels by the majorant grid ``Arrays.majorant`` ``[z, y, x]`` (1/mm, :func:`majorant_grid`): the largest
extinction any table entry in the block's value range gives (the range of every trilinear or tricubic B-spline
sample inside the block: ``_precompute.build_blocks``, dilated by one voxel, covers the B-spline's 4^3 taps).
With label maps, their solid structures' bound (``_medium.depth_bound``) raises every block to it.

:func:`free_flight` and :func:`transmittance` walk the grid's cells along a ray (Amanatides and Woo's
traversal), drawing exponential optical depths against each cell's majorant (regular tracking of the
piecewise-constant majorant): empty cells (majorant 0) cost one step, and the tentative collisions are as dense
as the block's densest value, not the whole volume's (Novak et al., "Monte Carlo methods for volumetric light
transport simulation", 2018, section 3.1):

* :func:`free_flight`: delta (Woodcock) tracking: a tentative collision is real with probability
  ``sigma_t / majorant``; returns the first real collision (a free-flight sample);
* :func:`transmittance`: ratio tracking: the weight is multiplied by ``1 - sigma_t / majorant`` at each tentative
  collision, an unbiased transmittance estimate (Russian roulette below 0.1).
"""

from __future__ import annotations

import math

import numpy as np

from ...jit import njit
from ._geometry import to_index
from ._medium import depth_at, frame_medium
from ._sobol import draw

__all__ = ["majorant_grid", "free_flight", "transmittance", "grid_walk", "advance_cell", "MAJ_BLOCK"]

#: block edge of the majorant grid (voxels)
MAJ_BLOCK = 8


def majorant_grid(sig: np.ndarray, bmin: np.ndarray, bmax: np.ndarray, scale: float) -> np.ndarray:
    """float32 majorants (1/mm) per block: ``scale * max(sig[floor(bmin) .. ceil(bmax)])`` (``bmin``, ``bmax``
    the block grids in table units)."""
    n = len(sig)
    lo = np.clip(np.floor(bmin).astype(np.int64), 0, n - 1)
    hi = np.clip(np.ceil(bmax).astype(np.int64), 0, n - 1)
    # sparse table of range maxima: level k holds max(sig[i .. i + 2^k - 1])
    levels = [np.asarray(sig, np.float64)]
    while (1 << len(levels)) <= n:
        prev, h = levels[-1], 1 << (len(levels) - 1)
        levels.append(np.maximum(prev[:-h], prev[h:]))
    span = np.maximum(hi - lo + 1, 1)
    k = np.floor(np.log2(span)).astype(np.int64)
    out = np.empty(lo.shape, np.float64)
    for level in np.unique(k):
        sel = k == level
        t = levels[level]
        out[sel] = np.maximum(t[lo[sel]], t[hi[sel] - (1 << level) + 1])
    return (out * scale * (1.0 + 1e-6)).astype(np.float32)


@njit(cache=True, fastmath=True, inline="always")
def _axis(o, d, c, size):
    """``(step, t of the next cell boundary, t per cell)`` of one axis from index coordinate ``o``."""
    if d > 0.0:
        return 1, ((c + 1) * size - o) / d, size / d
    if d < 0.0:
        return -1, (c * size - o) / d, -size / d
    return 0, 1e30, 1e30


@njit(cache=True, fastmath=True, inline="always")
def grid_walk(a, s, w, d, t0):
    """The grid walk of world ray ``w + t d`` from ``t0``: ``(o, di, cell, step, next, delta)`` as index-space
    triples (``o`` the origin, ``di`` the direction per mm, ``cell`` the cell at t0, then per axis the step, the t
    of the next boundary and the t per cell)."""
    g = a.majorant
    b = np.float64(s.majorant_block)
    oi, oj, ok = to_index(a.geo, w[0], w[1], w[2], 1.0)
    di, dj, dk = to_index(a.geo, d[0], d[1], d[2], 0.0)
    ci = min(max(int(math.floor((oi + t0 * di) / b)), 0), g.shape[2] - 1)
    cj = min(max(int(math.floor((oj + t0 * dj) / b)), 0), g.shape[1] - 1)
    ck = min(max(int(math.floor((ok + t0 * dk) / b)), 0), g.shape[0] - 1)
    si, ni, ei = _axis(oi, di, ci, b)
    sj, nj, ej = _axis(oj, dj, cj, b)
    sk, nk, ek = _axis(ok, dk, ck, b)
    return (oi, oj, ok), (di, dj, dk), (ci, cj, ck), (si, sj, sk), (ni, nj, nk), (ei, ej, ek)


@njit(cache=True, fastmath=True, inline="always")
def advance_cell(g, c, steps, nx, de):
    """The next cell along the walk: ``(cell, next, inside)``."""
    ci, cj, ck = c
    ni, nj, nk = nx
    if ni <= nj and ni <= nk:
        ci += steps[0]
        ni += de[0]
        inside = 0 <= ci < g.shape[2]
    elif nj <= nk:
        cj += steps[1]
        nj += de[1]
        inside = 0 <= cj < g.shape[1]
    else:
        ck += steps[2]
        nk += de[2]
        inside = 0 <= ck < g.shape[0]
    return (ci, cj, ck), (ni, nj, nk), inside


@njit(cache=True, fastmath=True, inline="always")
def _track(a, s, ray, span, ratio, key, dim, ctr):
    """Track along world ray ``ray = (w, d)``, ``w + t d`` (d unit), over ``span = (t0, t1)`` through the majorant
    grid, the table's optical depths per reference step scaled to 1/mm by ``kext / ds0``.

    Returns ``(hit, t, table index, weight, ctr)``: delta tracking (``ratio`` False): ``hit`` at the first real
    collision ``t`` (its table index), weight 1; ratio tracking: ``hit`` False, the transmittance estimate in
    ``weight``. The first uniform number is ``draw(key, dim)`` (``dim < 0``: none), the others draw dimensions
    ``ctr, ctr + 1, ...`` (returned advanced).
    """
    w, d = ray
    t0, t1 = span
    scale = s.extinction_scale / s.ds0
    g = a.majorant
    o, dv, c, steps, nx, de = grid_walk(a, s, w, d, t0)
    med = frame_medium(a, s)
    t = t0
    wt = 1.0
    if dim >= 0:
        u = draw(key, dim)
    else:
        u = draw(key, ctr)
        ctr += 1
    tau = -math.log(1.0 - u)
    while t < t1:
        tn = min(nx[0], nx[1], nx[2], t1)
        mu = g[c[2], c[1], c[0]]
        if mu > 0.0:
            while mu * (tn - t) > tau:
                t += tau / mu
                sg, idx = depth_at(med, o[0] + t * dv[0], o[1] + t * dv[1], o[2] + t * dv[2])
                sg *= scale
                if ratio:
                    wt *= max(1.0 - sg / mu, 0.0)
                    if wt < 0.1:  # Russian roulette: survive with probability 10 wt, weighing 0.1
                        if draw(key, ctr) * 0.1 >= wt:
                            return False, t, 0, 0.0, ctr + 1
                        ctr += 1
                        wt = 0.1
                elif draw(key, ctr) * mu < sg:
                    return True, t, idx, 1.0, ctr + 1
                else:
                    ctr += 1
                tau = -math.log(1.0 - draw(key, ctr))
                ctr += 1
            tau -= mu * (tn - t)
        t = tn
        c, nx, inside = advance_cell(g, c, steps, nx, de)
        if not inside:
            break
    return False, t1, 0, wt, ctr


@njit(cache=True, fastmath=True)
def free_flight(a, s, w, d, span, key, dim, ctr):
    """Delta tracking (:func:`_track`) over ``span = (t0, t1)``: ``(hit, t, table index, ctr)`` of the first real
    collision."""
    hit, t, idx, _, ctr = _track(a, s, (w, d), span, False, key, dim, ctr)
    return hit, t, idx, ctr


@njit(cache=True, fastmath=True)
def transmittance(a, s, w, d, span, key, ctr):
    """Ratio tracking (:func:`_track`) over ``span = (t0, t1)``: ``(transmittance estimate, ctr)``, every number
    from the hash dimensions."""
    _, _, _, wt, ctr = _track(a, s, (w, d), span, True, key, -1, ctr)
    return wt, ctr
