"""Empty-space skipping: a walk through the skipping grid's blocks along the ray (3-D DDA).

The walk keeps the block it stands in as three integers and the ray parameter ``tc`` at which the ray enters it.
At each block it asks the mode's ``radius`` (``_pieces``: composite -- no visible value in the block's range,
else the side of the largest empty cube of blocks that starts at the block and extends the way the ray goes, the
ray's octant's row of ``Arrays.skip_flags`` (``_octants``); isosurface -- the same of the blocks the threshold is
outside the range of; mip / minip -- the block cannot beat the running max / min):

* a block that can contribute is sampled: the first sample of the ray's grid at or past ``tc`` is returned if
  it lies in the block, with the ray parameter at which the ray leaves the block (under adaptive sampling, the
  cube of coarse blocks ahead of it, ``Arrays.coarse_flags``, per octant as well); else the walk goes on;
* a block that cannot is passed over: with radius 1 to the neighbour across the nearest face (integer steps, the
  faces' parameters from the indices: no float-to-int conversion), with a larger one past the whole cube of
  empty blocks ahead (its far faces are those of the cube of that radius less one around the block).

A sample lies in the block whose parameter interval holds it, up to rounding at a face; every block's range is
taken over its voxels dilated by one (``_precompute.build_blocks``), so a sample within rounding of a face is
also bounded by the block on the other side, and skipping changes no pixel. The walk leaves the grid where the
ray leaves the volume: past the grid's last block on an axis the samples read the clamped border voxels of that
block, so that block's exit on the axis is taken as never.

Modes that are not ``eager`` (pre-integration, the projections) need the sample before a skipped run: after a
taken sample, the walk goes on block by block and returns the first sample in a block that cannot contribute;
only the samples after it are passed over.

Samples are placed by their parameter as the loop takes them (:func:`sample_t`, at most the ray's exit ``t1``),
and a block entered exactly at ``t1`` is still asked: a ray leaving the volume on a face of the grid keeps its
last sample there.
"""

from __future__ import annotations

import math
from typing import NamedTuple

from ...jit import njit
from ._frame import FAR
from ._octants import octant
from ._pieces import eager, radius

__all__ = ["enter", "walk", "sample_t", "Cursor"]


class Cursor(NamedTuple):
    """Where the walk stands: its block, the ray parameter at which the ray enters it, and whether the last sample
    returned lies in a block that cannot contribute."""

    bk: int           #: block index along z
    bj: int           #: along y
    bi: int           #: along x
    tc: float         #: the ray parameter at which the ray enters the block
    prev_skip: bool   #: the sample returned last lies in a block that cannot contribute


@njit(cache=True, fastmath=True, inline="always")
def _block_index(o, d, t, inv_b, g):
    """The block index (clamped to ``0 .. g - 1``) on one axis at ray parameter ``t``."""
    return min(max(int((o + t * d) * inv_b), 0), g - 1)


@njit(cache=True, fastmath=True, inline="always")
def enter(r, a, s, t):
    """The block ``(bk, bj, bi)`` holding the point of the ray at parameter ``t``."""
    gz, gy, gx = a.bmin.shape  # the block grid (bflag: octants first, a placeholder in mip)
    inv_b = 1.0 / s.block
    return (_block_index(r.ok, r.dk, t, inv_b, gz), _block_index(r.oj, r.dj, t, inv_b, gy),
            _block_index(r.oi, r.di, t, inv_b, gx))


@njit(cache=True, fastmath=True, inline="always")
def _face(o, d, b, rad, size, g):
    """The ray parameter at which the ray leaves blocks ``b - rad + 1 .. b + rad - 1`` on one axis (the index ray
    ``o + t d``); ``FAR`` where it does not, or leaves the grid there."""
    if d > 0.0:
        return FAR if b + rad >= g else ((b + rad) * size - o) / d
    if d < 0.0:
        return FAR if b - rad < 0 else ((b - rad + 1) * size - o) / d
    return FAR


@njit(cache=True, fastmath=True, inline="always")
def _past(r, a, s, bk, bj, bi, rad):
    """``(bk, bj, bi, t)``: the block past the cube of ``rad`` blocks from block ``(bk, bj, bi)`` the way the ray
    goes (its far faces: those of the cube of radius ``rad - 1`` around the block), and the ray parameter ``t`` at
    which the ray enters it (``FAR``: it never does). The exit axis moves by ``rad`` (integer
    steps: the walk always gets on); with ``rad > 1`` the other two come from the ray's point there."""
    gz, gy, gx = a.bmin.shape  # the block grid (bflag: octants first, a placeholder in mip)
    fi = _face(r.oi, r.di, bi, rad, s.block, gx)
    fj = _face(r.oj, r.dj, bj, rad, s.block, gy)
    fk = _face(r.ok, r.dk, bk, rad, s.block, gz)
    te = min(fi, fj, fk)
    ek, ej, ei = enter(r, a, s, te) if rad > 1 else (bk, bj, bi)
    if fi == te:
        return ek, ej, bi + (rad if r.di > 0.0 else -rad), te
    if fj == te:
        return ek, bj + (rad if r.dj > 0.0 else -rad), ei, te
    return bk + (rad if r.dk > 0.0 else -rad), ej, ei, te


@njit(cache=True, fastmath=True, inline="always")
def sample_t(r, s, k):
    """The ray parameter of sample ``k``, as the loop takes it: at most ``r.t1`` (the last sample of a ray can
    lie a little past its exit; it is taken at the exit)."""
    return min(r.t0 + (k + r.jit) * s.ds, r.t1)


@njit(cache=True, fastmath=True, inline="always")
def _first(r, s, k, tc):
    """The first sample at or past parameter ``tc`` (``tc <= r.t1``), not before sample ``k`` (``k`` itself when
    it is past ``tc``: rounding in the division never passes over it)."""
    if sample_t(r, s, k) >= tc:
        return k
    return max(k, int(math.ceil((tc - r.t0) / s.ds - r.jit)))


@njit(cache=True, fastmath=True, inline="always")
def walk(mode, r, a, s, st, k, cur):
    """From sample ``k`` and the walk's :class:`Cursor` ``cur``, to the next sample to take:
    ``(k, t_check, coarse, cursor)`` -- the sample (``r.k1``: none is left), the parameter past which the walk
    must be asked again, whether the sample stands in a cube of coarse blocks, and the walk's next cursor. A
    sample belongs to the block whose interval ``[entry, exit)`` holds its parameter (:func:`sample_t`); a block
    entered at ``r.t1`` still holds the last sample."""
    bk, bj, bi, tc, prev_skip = cur.bk, cur.bj, cur.bi, cur.tc, cur.prev_skip
    o = octant(r)
    while tc <= r.t1:
        rad = radius(mode, a, s, st, o, bk, bj, bi)
        take_empty = rad > 0 and not (prev_skip or eager(mode))  # the first sample of a skipped run is taken
        coarse = rad <= 0 and s.stride > 1 and a.coarse_flags[o, bk, bj, bi] > 0
        r1 = 1 if take_empty else max(int(a.coarse_flags[o, bk, bj, bi]) if coarse else rad, 1)
        nk, nj, ni, te = _past(r, a, s, bk, bj, bi, r1)
        if rad <= 0 or take_empty:
            kk = _first(r, s, k, tc)
            if kk >= r.k1:
                break
            if sample_t(r, s, kk) < te:
                if take_empty:  # asked again at the next sample, from this block
                    return kk, sample_t(r, s, kk), False, Cursor(bk, bj, bi, tc, True)
                return kk, te, coarse, Cursor(nk, nj, ni, te, False)
        bk, bj, bi, tc = nk, nj, ni, te
    return r.k1, FAR, False, Cursor(bk, bj, bi, tc, True)
