"""Connected components of triangle meshes (vertices joined by triangle edges)."""

from __future__ import annotations

import numpy as np

from ._mesh import Mesh

__all__ = ["mesh_components", "largest_component", "submesh"]


def mesh_components(mesh: Mesh) -> tuple[int, np.ndarray]:
    """Label the connected pieces of a mesh.

    Returns
    -------
    n : int
        Number of pieces (isolated vertices count as pieces of their own).
    labels : (N,) int32
        Piece of each vertex; a face's piece is that of its first vertex.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    f = mesh.faces.astype(np.int64)
    nv = mesh.n_vertices
    rows = np.concatenate([f[:, 0], f[:, 1], f[:, 2]])
    cols = np.concatenate([f[:, 1], f[:, 2], f[:, 0]])
    graph = coo_matrix((np.ones(len(rows), np.int8), (rows, cols)), shape=(nv, nv)).tocsr()
    n, labels = connected_components(graph, directed=False)
    return int(n), labels.astype(np.int32)


def submesh(mesh: Mesh, face_mask: np.ndarray) -> Mesh:
    """The faces selected by ``face_mask`` (M,) bool, with their vertices renumbered compactly."""
    faces = mesh.faces[np.asarray(face_mask, bool)]
    used = np.zeros(mesh.n_vertices, np.bool_)
    used[faces.ravel()] = True
    new_index = np.cumsum(used) - 1
    out = Mesh.__new__(Mesh)  # a subset of a valid mesh is valid
    out.vertices = mesh.vertices[used]
    out.faces = new_index[faces].astype(mesh.faces.dtype)
    out.normals = mesh.normals[used]
    out.voxel_vertices = None if mesh.voxel_vertices is None else mesh.voxel_vertices[used]
    out.meta = dict(mesh.meta)
    return out


def largest_component(mesh: Mesh) -> Mesh:
    """The connected piece with the most triangles (ties: the lowest label)."""
    if mesh.n_faces == 0:
        return mesh
    _, labels = mesh_components(mesh)
    face_label = labels[mesh.faces[:, 0]]
    biggest = np.argmax(np.bincount(face_label))
    return submesh(mesh, face_label == biggest)
