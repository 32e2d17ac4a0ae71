"""Mesh smoothing: Laplacian (umbrella) and Taubin's lambda/mu, vectorised with a sparse adjacency."""

from __future__ import annotations

import numpy as np

from ._mesh import Mesh

__all__ = ["taubin_smooth", "laplacian_smooth"]


def _umbrella(mesh: Mesh):
    """Row-normalised vertex adjacency W (sparse CSR): ``W @ v`` is the mean of each vertex's neighbours."""
    from scipy.sparse import coo_matrix, diags

    f = mesh.faces.astype(np.int64)
    nv = mesh.n_vertices
    i = np.concatenate([f[:, 0], f[:, 1], f[:, 2], f[:, 1], f[:, 2], f[:, 0]])
    j = np.concatenate([f[:, 1], f[:, 2], f[:, 0], f[:, 0], f[:, 1], f[:, 2]])
    adj = coo_matrix((np.ones(len(i)), (i, j)), shape=(nv, nv)).tocsr()
    adj.data[:] = 1.0  # interior edges appear twice; weight each neighbour once
    deg = np.asarray(adj.sum(axis=1)).ravel()
    return diags(1.0 / np.maximum(deg, 1.0)) @ adj, deg > 0


def _smooth(mesh: Mesh, iterations: int, factors: tuple[float, ...]) -> Mesh:
    if iterations < 0:
        raise ValueError(f"iterations must be >= 0, got {iterations}")
    if iterations == 0 or mesh.n_faces == 0:
        return mesh
    w, used = _umbrella(mesh)
    v = mesh.vertices.astype(np.float64)
    for _ in range(iterations):
        for k in factors:
            d = w @ v - v
            d[~used] = 0.0
            v += k * d
    return mesh.with_geometry(v.astype(np.float32))


def laplacian_smooth(mesh: Mesh, iterations: int = 10, lam: float = 0.5) -> Mesh:
    """Umbrella Laplacian smoothing: ``v += lam * (mean(neighbours) - v)``, repeated.

    Shrinks closed surfaces; prefer :func:`taubin_smooth`. Vertex positions in mm;
    normals are recomputed from the faces.
    """
    return _smooth(mesh, iterations, (lam,))


def taubin_smooth(mesh: Mesh, iterations: int = 10, lam: float = 0.5, mu: float = -0.53) -> Mesh:
    """Taubin's low-pass smoothing: alternating Laplacian steps of ``lam > 0`` and ``mu < -lam``.

    Each iteration is one shrinking step (``lam``) and one inflating step (``mu``), which
    removes high-frequency noise (marching-cubes terraces) while keeping the volume
    nearly unchanged. Normals are recomputed from the faces.

    References
    ----------
    Taubin, G. "A signal processing approach to fair surface design", SIGGRAPH 1995.
    """
    if not (lam > 0 and mu < -lam):
        raise ValueError(f"Taubin smoothing needs lam > 0 and mu < -lam, got lam={lam}, mu={mu}")
    return _smooth(mesh, iterations, (lam, mu))
