"""What marching cubes' passes hand their kernels, declared once (as ``render/raycast/_frame.py`` does for a frame).

Each pass's kernel takes whole records and reads fields by name (``g.vol``, ``out.faces``). Numba compiles a
NamedTuple argument as a struct of its fields, so a record costs what its fields passed one by one cost, and
compiles one variant per combination of field types, as the fields did. Arrays are indexed ``[z, y, x]``;
per-row arrays by grid row ``r = z * ny + y``, per-cube-row arrays by ``z * (ny - 1) + y`` (see ``_mc_kernel``).
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

__all__ = ["Sign", "SignOut", "Grid", "Counts", "Emit", "Out"]


class Sign(NamedTuple):
    """What pass 1 (``_mc_rows.sign_rows``) reads."""

    vol: np.ndarray    #: samples [z, y, x] in their own dtype
    level: Any         #: the level in the samples' dtype (``_mc_rows.threshold``): inside is ``vol > level``
    sgn: np.ndarray    #: flag rows, uint8 (nz * ny + 2, 8 * nw): written for rows with inside and outside samples
    words: np.ndarray  #: ``sgn`` viewed as uint64 (nz * ny + 2, nw)
    bits: np.ndarray   #: float32 ``vol`` viewed as uint32 (the NaN/infinity check), else an empty (0, 0, 0) array


class SignOut(NamedTuple):
    """What pass 1 writes per grid row."""

    nxc: np.ndarray      #: crossed x edges, int64
    trim: np.ndarray     #: ``(lo, hi, ends, flag row)`` (nz * ny, 4) int64 (``_mc_rows``)
    ninside: np.ndarray  #: samples above the level, int64
    nbad: np.ndarray     #: NaN and infinite samples, int64


class Grid(NamedTuple):
    """What passes 2 and 3 read: the samples, the level and pass 1's flags."""

    vol: np.ndarray    #: samples [z, y, x] in their own dtype, each read as its float32 value
    level: Any         #: the level, float32
    words: np.ndarray  #: pass 1's flag rows as uint64 words
    trim: np.ndarray   #: pass 1's trims (nz * ny, 4) int64
    mask: np.ndarray   #: cubes [z, y, x] that make triangles, bool; a (1, 1, 1) dummy when unused
    use_mask: bool     #: whether ``mask`` is used


class Counts(NamedTuple):
    """What pass 2 (``_mc_kernel.count_rows``) writes."""

    nyc: np.ndarray   #: crossed y edges per grid row, int64
    nzc: np.ndarray   #: crossed z edges per grid row, int64
    ntri: np.ndarray  #: triangles per cube row, int64
    ncen: np.ndarray  #: centre vertices per cube row, int64


class Emit(NamedTuple):
    """What pass 3 (``_mc_kernel.emit_rows``) reads besides :class:`Grid`: where each row's output starts and
    how index positions become world positions."""

    nxc: np.ndarray    #: crossed x edges per grid row, int64
    nyc: np.ndarray    #: crossed y edges per grid row, int64
    vbase: np.ndarray  #: first vertex of each grid row's crossed edges, int64
    tbase: np.ndarray  #: first triangle of each cube row, int64
    cbase: np.ndarray  #: first centre vertex of each cube row, int64
    aff: np.ndarray    #: voxel (i, j, k) -> world mm, (4, 4) float64
    nmat: np.ndarray   #: index-space gradient -> world-space normal, (3, 3) float64 (inverse transpose)
    flip: bool         #: the affine mirrors: triangles wound the other way


class Out(NamedTuple):
    """What pass 3 writes per vertex and per triangle."""

    ijk: np.ndarray    #: index coordinates (i, j, k) float32, (0, 3) when not asked for
    xyz: np.ndarray    #: world mm float32
    nrm: np.ndarray    #: unit outward normals float32
    faces: np.ndarray  #: triangles, int32 vertex numbers
