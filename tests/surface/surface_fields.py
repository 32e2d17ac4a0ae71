"""Fields and mesh checks for the surface tests: smooth signed-distance-like functions sampled at voxel centres."""

from __future__ import annotations

import numpy as np

from volumen.core import Volume


def ellipsoid_field(shape, semi_axes_mm, spacing=(1.0, 1.0, 1.0), centre_mm=None) -> Volume:
    """Positive inside the ellipsoid ``(x/a)^2 + (y/b)^2 + (z/c)^2 = 1`` (semi-axes (a, b, c) mm along x, y, z).

    The value is ``(1 - q) * min(a, b, c)`` with q the ellipsoidal radius, close to a signed
    distance in mm near the surface; level 0 is the ellipsoid exactly.
    """
    nz, ny, nx = shape
    dz, dy, dx = spacing
    if centre_mm is None:
        centre_mm = ((nx - 1) * dx / 2 + 0.31, (ny - 1) * dy / 2 - 0.17, (nz - 1) * dz / 2 + 0.23)
    a, b, c = semi_axes_mm
    z = np.arange(nz)[:, None, None] * dz - centre_mm[2]
    y = np.arange(ny)[None, :, None] * dy - centre_mm[1]
    x = np.arange(nx)[None, None, :] * dx - centre_mm[0]
    q = np.sqrt((x / a) ** 2 + (y / b) ** 2 + (z / c) ** 2)
    data = ((1.0 - q) * min(a, b, c)).astype(np.float32)
    vol = Volume(data, spacing=spacing)
    vol.meta["centre_mm"] = np.array(centre_mm)
    return vol


def ellipsoid_area(a: float, b: float, c: float) -> float:
    """Exact surface area of an ellipsoid (Legendre's elliptic-integral formula)."""
    from scipy.special import ellipeinc, ellipkinc

    a, b, c = sorted((a, b, c), reverse=True)
    if np.isclose(a, c):
        return 4 * np.pi * a * a
    phi = np.arccos(c / a)
    m = (a * a * (b * b - c * c)) / (b * b * (a * a - c * c))
    s = np.sin(phi)
    legendre = ellipeinc(phi, m) * s * s + ellipkinc(phi, m) * np.cos(phi) ** 2
    return float(2 * np.pi * c * c + 2 * np.pi * a * b / s * legendre)


def edge_counts(faces: np.ndarray) -> np.ndarray:
    """How many triangles share each undirected edge (one int64 key per edge: a sort of keys, not of rows)."""
    from volumen.surface._check import edge_keys

    return np.unique(edge_keys(faces, int(faces.max(initial=0)) + 1), return_counts=True)[1]


def directed_edges_unique(faces: np.ndarray) -> bool:
    """True when no directed edge repeats: neighbouring triangles wind consistently."""
    d = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]).astype(np.int64)
    key = d[:, 0] * (d.max() + 1) + d[:, 1]
    return len(np.unique(key)) == len(key)


def welded_inner_edges(mesh, shape) -> tuple[np.ndarray, int]:
    """``(counts, collapsed)``: with corners joined by position as an STL reader does (triangles with two corners
    on one point dropped, ``collapsed`` of them), the triangles of each edge away from the border of a volume of
    ``shape`` [z, y, x] (not both ends on its boundary)."""
    from volumen.surface._check import edge_keys, welded

    label, first = welded(mesh.vertices)
    f = label[mesh.faces.astype(np.int64)]
    ok = (f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 2] != f[:, 0])
    top = np.array(shape[::-1]) - 1  # (i, j, k) of the last sample
    ijk = mesh.voxel_vertices[first]
    on_border = ((ijk < 1e-4) | (ijk > top - 1e-4)).any(axis=1)
    key, counts = np.unique(edge_keys(f[ok], len(first)), return_counts=True)
    inner = ~(on_border[key // len(first)] & on_border[key % len(first)])
    return counts[inner], int((~ok).sum())


def crossing_distances(a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    """Edge crossings of two extractors (voxel coordinates, same axis order): the largest distance from a crossing
    of either to the nearest of the other, ``(elsewhere, near a grid point)``. Ours keep ``T_MIN`` voxel off grid
    points (``_mc_kernel.T_MIN``) where scikit-image may put a crossing on one, so crossings within that of a grid
    point are the second maximum."""
    from scipy.spatial import cKDTree

    from volumen.surface._mc_kernel import T_MIN

    d = np.concatenate([cKDTree(b).query(a)[0], cKDTree(a).query(b)[0]])
    near = np.concatenate([np.abs(v - np.round(v)).max(axis=1) <= T_MIN + 1e-5 for v in (a, b)])
    return float(d[~near].max(initial=0.0)), float(d[near].max(initial=0.0))
