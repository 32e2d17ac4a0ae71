"""Surface area and enclosed volume of triangle meshes."""

from __future__ import annotations

import numpy as np

__all__ = ["surface_area", "enclosed_volume"]


def _corners(mesh) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    v = np.asarray(mesh.vertices, dtype=np.float64)
    f = np.asarray(mesh.faces, dtype=np.int64)
    return v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]


def surface_area(mesh) -> float:
    """Total triangle area in mm^2 (world units squared), accumulated in float64."""
    if mesh.n_faces == 0:
        return 0.0
    a, b, c = _corners(mesh)
    return float(0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1).sum())


def enclosed_volume(mesh) -> float:
    """Signed enclosed volume in mm^3 by the divergence theorem.

    ``V = sum(a . (b x c)) / 6`` over the triangles; positive when the mesh is closed
    and its faces are wound counter-clockwise seen from outside (outward normals),
    negative when they face inward. Triangles are shifted to the vertex centroid first,
    which keeps the sum accurate far from the origin. On an open mesh the value depends
    on that origin and is not a volume.
    """
    if mesh.n_faces == 0:
        return 0.0
    a, b, c = _corners(mesh)
    o = np.asarray(mesh.vertices, dtype=np.float64).mean(axis=0)
    a, b, c = a - o, b - o, c - o
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)
