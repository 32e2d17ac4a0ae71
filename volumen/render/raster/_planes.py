"""Where the slicing planes go, and their polygons: view-aligned planes cut against the volume box.

Planes are perpendicular to the view direction ``forward`` and placed by their
view depth ``z = dot(p - position, forward)`` (mm). Each plane stands for a slab
between two *boundaries*: plane ``k`` lies in the middle of
``[b_k, b_{k+1}]`` and its slab thickness ``gap_k = b_{k+1} - b_k`` is what the
opacity is corrected for (a ray crossing the slab at angle ``theta`` to
``forward`` travels ``gap_k / cos(theta)`` through it). Slabs tile the depth
range exactly, so a whole number of slabs covers the volume and the picture
does not depend on the spacing.

Distributions (``ADAPTIVE``), over the depth range ``[z0, z1]`` (near to far,
``L = z1 - z0``) with ``ds0`` the smallest voxel spacing and ``D`` the volume
diagonal:

* ``"uniform"``: ``n = ceil(L spv / ds0)`` planes evenly (at most the diagonal in
  voxels times the samples per voxel, seen along the diagonal);
* ``"near-quarter"``: the same ``n`` planes, 2/3 of them in the first quarter
  of ``[z0, z1]`` and 1/3 in the rest;
* ``"diagonal-quarter"``: the same ``n``, 2/3 within ``D / 4`` of ``z0``;
* ``"two-per-voxel"``: spacing ``ds0 / 2`` everywhere;
* ``"two-then-one"``: spacing ``ds0 / 2`` up to ``z0 + D / 4``, ``ds0`` beyond.

The first four adaptive schemes follow the fly-through study of the source; they
matter with a perspective camera inside the volume, where near planes cover
few pixels each and far ones many.
"""

from __future__ import annotations

from typing import Literal, get_args

import numpy as np

__all__ = ["ADAPTIVE", "Planes", "slab_boundaries", "slice_polygons", "box_corners"]

Planes = Literal["uniform", "near-quarter", "diagonal-quarter", "two-per-voxel", "two-then-one"]
ADAPTIVE: tuple[str, ...] = get_args(Planes)

# the 12 edges of a box whose corner c has bits (i, j, k) = (c & 1, c >> 1 & 1, c >> 2 & 1)
_EDGES = np.array([(c, c | b) for b in (1, 2, 4) for c in range(8) if not c & b], np.int64)


def _even(a: float, b: float, n: int) -> np.ndarray:
    return np.linspace(a, b, max(int(n), 1) + 1)


def _stepped(a: float, b: float, step: float) -> np.ndarray:
    """Boundaries from a to b at ``step`` (the last slab shortened to end exactly at b)."""
    if b <= a:
        return np.array([a])
    n = int(np.ceil((b - a) / step - 1e-9))
    out = a + step * np.arange(n + 1)
    out[-1] = b
    return out


def slab_boundaries(mode: str, z0: float, z1: float, *, ds0: float, spv: float, diagonal: float) -> np.ndarray:
    """Slab boundaries (float64, increasing, first ``z0``, last ``z1``, mm of view depth) of a distribution.

    Parameters
    ----------
    mode : one of :data:`ADAPTIVE`
    z0, z1 : float, mm
        Near and far view depth of the part of the volume to slice.
    ds0 : float, mm
        Reference step: the smallest voxel spacing.
    spv : float
        Samples per voxel (``uniform``, ``near-quarter``, ``diagonal-quarter``).
    diagonal : float, mm
        The volume's diagonal ``D``.
    """
    if mode not in ADAPTIVE:
        raise ValueError(f"plane distribution must be one of {', '.join(map(repr, ADAPTIVE))}; got {mode!r}")
    length = z1 - z0
    if not length > 0:
        return np.array([z0, max(z1, z0)])
    n = max(int(np.ceil(length * spv / ds0 - 1e-9)), 1)
    if mode == "uniform":
        return _even(z0, z1, n)
    if mode in ("near-quarter", "diagonal-quarter"):
        split = z0 + (0.25 * length if mode == "near-quarter" else 0.25 * diagonal)
        if split >= z1 or n < 3:
            return _even(z0, z1, n)
        n_near = int(round(2 * n / 3))
        return np.concatenate([_even(z0, split, n_near), _even(split, z1, n - n_near)[1:]])
    if mode == "two-per-voxel":
        return _stepped(z0, z1, ds0 / 2)
    split = min(z0 + 0.25 * diagonal, z1)  # two-then-one
    near = _stepped(z0, split, ds0 / 2)
    return np.concatenate([near, _stepped(split, z1, ds0)[1:]]) if split < z1 else near


def box_corners(lo, hi, affine) -> np.ndarray:
    """(8, 3) world mm of the index-space box ``[lo, hi]`` (each (3,) = i, j, k), corner c = bits (i, j, k)."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    bits = (np.arange(8)[:, None] >> np.arange(3)[None, :]) & 1
    ijk = np.where(bits == 1, hi, lo)
    a = np.asarray(affine, float)
    return ijk @ a[:3, :3].T + a[:3, 3]


def slice_polygons(corners: np.ndarray, eye, basis, depths: np.ndarray):
    """Cut planes of view depth ``depths`` against a box; triangle fans of the polygons.

    Parameters
    ----------
    corners : (8, 3) float, world mm
        The box (a parallelepiped), corner ``c`` at bits ``(i, j, k)`` of c.
    eye : (3,) float, world mm
        Camera position (depth origin).
    basis : (right, up, forward), each (3,) unit
    depths : (n,) float, mm
        View depth of each plane, in drawing order.

    Returns
    -------
    vertices : (n * 12, 3) float32, world mm
        Up to six polygon corners per plane, ordered around the polygon's
        centroid (the rest of the plane's 12 rows repeat the centroid).
    triangles : (m, 3) int32
        Fan triangles ``(0, j, j + 1)`` of each polygon, plane after plane in
        the order of ``depths``.
    first : (n + 1,) int64
        Triangle offsets: plane ``p`` owns ``triangles[first[p]:first[p + 1]]``.
    """
    r, u, f = (np.asarray(v, float) for v in basis)
    c = np.asarray(corners, float)
    d = np.asarray(depths, float)
    s = (c - np.asarray(eye, float)) @ f                     # (8,) corner depths
    a, b = _EDGES[:, 0], _EDGES[:, 1]
    sa, sb = s[a], s[b]
    den = sb - sa
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (d[:, None] - sa[None, :]) / den[None, :]        # (n, 12)
    valid = (den[None, :] != 0) & (t >= 0) & (t <= 1)
    t = np.where(valid, t, 0.0)
    pts = c[a][None] + t[..., None] * (c[b] - c[a])[None]    # (n, 12, 3)
    count = valid.sum(axis=1)
    centroid = (pts * valid[..., None]).sum(axis=1) / np.maximum(count, 1)[:, None]
    rel = pts - centroid[:, None, :]
    ang = np.where(valid, np.arctan2(rel @ u, rel @ r), np.inf)
    order = np.argsort(ang, axis=1, kind="stable")
    pts = np.take_along_axis(pts, order[..., None], axis=1)
    filled = np.arange(12)[None, :] < count[:, None]
    pts = np.where(filled[..., None], pts, centroid[:, None, :])
    # fans: triangle j of a plane = (0, j + 1, j + 2), kept while j + 2 < count
    j = np.arange(10)
    keep = (j[None, :] + 2) < count[:, None]                 # (n, 10)
    base = (np.arange(len(d)) * 12)[:, None]
    tri = np.stack([np.broadcast_to(base, keep.shape), base + j + 1, base + j + 2], axis=-1)
    triangles = tri[keep].astype(np.int32)
    first = np.concatenate([[0], np.cumsum(keep.sum(axis=1))]).astype(np.int64)
    return pts.reshape(-1, 3).astype(np.float32), triangles, first
