"""Mesh decimation to a target triangle count (quadric error metrics, fast-simplification)."""

from __future__ import annotations

import numpy as np

from ._mesh import Mesh

__all__ = ["decimate"]


def decimate(mesh: Mesh, target_triangles: int, *, aggressiveness: float = 7.0) -> Mesh:
    """Reduce a mesh to about ``target_triangles`` triangles by quadric edge collapse.

    Uses ``fast_simplification`` (Fast-Quadric-Mesh-Simplification). The count reached
    is usually within a few percent of the target. A mesh already at or below the
    target is returned as it is. Normals are recomputed from the faces.

    References
    ----------
    Garland, M. and Heckbert, P. "Surface simplification using quadric error metrics",
    SIGGRAPH 1997.
    """
    target = int(target_triangles)
    if target < 4:
        raise ValueError(f"target_triangles must be at least 4, got {target_triangles}")
    if mesh.n_faces <= target:
        return mesh
    import fast_simplification

    points, faces = fast_simplification.simplify(
        mesh.vertices.astype(np.float32), mesh.faces.astype(np.int32),
        target_reduction=1.0 - target / mesh.n_faces, agg=aggressiveness)
    return mesh.with_geometry(np.asarray(points, np.float32), np.asarray(faces, np.int64),
                              decimated_from=mesh.n_faces)
