"""Direction-dependent skip distances: per block and per octant of ray directions, the side of the largest empty
cube of blocks that starts at the block and extends the way the ray goes.

A ray whose index-space direction has signs ``(sz, sy, sx)`` (octant ``4 (dk < 0) + 2 (dj < 0) + (di < 0)``) that
stands in block ``b`` stays inside the blocks ``b .. b + s (r - 1)`` (per axis, ``s`` the sign) until it crosses one
of their far faces. When all of them are empty, the walk (``_walk``) jumps to that crossing: the same faces as the
symmetric (Chebyshev) distance's cube of radius ``r - 1`` around ``b``, whose far faces are at the same place. Only
the blocks ahead of the ray count, so the jump is at least as long, and longer where the visible blocks lie behind
or beside the ray (the ribs around a lung, seen from inside it).

``side[o, b] = 0`` where the block can contribute, else ``1 + min`` of ``side[o]`` over the 7 blocks ``b + s e``
(``e`` in ``{0, 1}^3``, not 0): the largest empty square's recurrence in three dimensions. Past the grid counts as
empty (the walk ends there), capped at 255. The smallest of the eight is the Chebyshev distance
(``tests/render/test_walk.py``): the eight cubes of side ``r`` at ``b`` tile the symmetric cube of radius ``r - 1``.
"""

from __future__ import annotations

import numpy as np

from ...jit import njit, run_parts

__all__ = ["octant_sides", "octant", "tiled"]

CAP = 255


@njit(cache=True, nogil=True)
def _sides_kernel(part, parts, flags, side):
    """Octants ``part * 8 // parts`` .. of ``side`` (``volumen.jit.run_parts``)."""
    gz, gy, gx = flags.shape
    for o in range(part * 8 // parts, (part + 1) * 8 // parts):
        sz, sy, sx = (-1 if o & 4 else 1), (-1 if o & 2 else 1), (-1 if o & 1 else 1)
        for kk in range(gz):
            k = gz - 1 - kk if sz > 0 else kk
            k1 = k + sz
            for jj in range(gy):
                j = gy - 1 - jj if sy > 0 else jj
                j1 = j + sy
                for ii in range(gx):
                    i = gx - 1 - ii if sx > 0 else ii
                    if flags[k, j, i]:
                        side[o, k, j, i] = 0
                        continue
                    i1 = i + sx
                    m = CAP
                    for dk in range(2):
                        kn = k1 if dk else k
                        if kn < 0 or kn >= gz:
                            continue
                        for dj in range(2):
                            jn = j1 if dj else j
                            if jn < 0 or jn >= gy:
                                continue
                            for di in range(2):
                                if dk + dj + di == 0:
                                    continue
                                ni = i1 if di else i
                                if ni < 0 or ni >= gx:
                                    continue
                                m = min(m, side[o, kn, jn, ni])
                    side[o, k, j, i] = min(m + 1, CAP)


def octant_sides(flags: np.ndarray) -> np.ndarray:
    """uint8 ``(8, gz, gy, gx)``: for each octant of ray directions, the side in blocks of the largest cube of
    blocks with no ``flags`` set (1 = can contribute) that starts at the block and extends the octant's way."""
    flags = np.ascontiguousarray(flags, np.uint8)
    side = np.empty((8,) + flags.shape, np.uint8)
    run_parts(_sides_kernel, 8, flags, side)
    return side


@njit(cache=True, fastmath=True, inline="always")
def octant(r):
    """The octant of ray ``r``'s index-space direction (its row of :func:`octant_sides`)."""
    return (4 if r.dk < 0.0 else 0) + (2 if r.dj < 0.0 else 0) + (1 if r.di < 0.0 else 0)


def tiled(side: np.ndarray) -> np.ndarray:
    """The eight octants' grids of ``side`` ``(8, gz, gy, gx)`` as one ``(2 gz, 2 gy, 2 gx)`` grid, octant ``o`` at
    the offset ``(gz if o & 4, gy if o & 2, gx if o & 1)``: the gl ray caster's texture (``raycast_modes.glsl``),
    each side twice the block grid's (at most the volume's side plus one). A placeholder ``(1, 1, 1, 1)`` (no
    skipping, or a mode that reads none) stays one texel."""
    g = side.shape[1:]
    if side.shape[0] == 1:
        return side.reshape(g)
    return np.ascontiguousarray(side.reshape(2, 2, 2, *g).transpose(0, 3, 1, 4, 2, 5).reshape(2 * g[0], 2 * g[1],
                                                                                              2 * g[2]))
