"""Consistent outward orientation of triangle meshes."""

from __future__ import annotations

import numpy as np

from ._mesh import Mesh

__all__ = ["orient_outward"]


def _face_adjacency(faces: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Pairs of faces sharing an edge used by exactly two faces: ``(a, b, same)``.

    ``same`` is True when both faces walk the shared edge in the same direction,
    i.e. their windings disagree.
    """
    f = faces.astype(np.int64)
    m = len(f)
    a = np.concatenate([f[:, 0], f[:, 1], f[:, 2]])
    b = np.concatenate([f[:, 1], f[:, 2], f[:, 0]])
    face = np.tile(np.arange(m), 3)
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    key = lo * (int(f.max()) + 1) + hi
    order = np.argsort(key, kind="stable")
    key, face, fwd = key[order], face[order], (a < b)[order]
    start = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
    count = np.diff(np.r_[start, len(key)])
    pair = start[count == 2]  # manifold edges only
    return face[pair], face[pair + 1], fwd[pair] == fwd[pair + 1]


def orient_outward(mesh: Mesh) -> Mesh:
    """Wind every connected piece consistently, with normals pointing outward.

    Faces are flipped so neighbours across each manifold edge agree (a breadth-first
    walk per piece), then each piece whose signed enclosed volume is negative is turned
    inside out. Meant for closed pieces; for an open piece "outward" is the side its
    divergence-theorem volume about the piece's centroid calls positive. Vertex normals
    are recomputed from the faces.
    """
    if mesh.n_faces == 0:
        return mesh
    faces = mesh.faces.astype(np.int64)
    a, b, same = _face_adjacency(faces)
    src = np.concatenate([a, b])
    dst = np.concatenate([b, a])
    flag = np.concatenate([same, same]).astype(np.bool_)
    order = np.argsort(src, kind="stable")
    nbr, nbr_same = dst[order], flag[order]
    nbr_ptr = np.zeros(len(faces) + 1, np.int64)
    np.cumsum(np.bincount(src, minlength=len(faces)), out=nbr_ptr[1:])
    flip = np.zeros(len(faces), np.bool_)
    comp = np.full(len(faces), -1, np.int64)
    from ._orient_kernel import propagate

    n_comp = propagate(len(faces), nbr_ptr, nbr, nbr_same, flip, comp)
    faces[flip] = faces[flip][:, ::-1]
    v = mesh.vertices.astype(np.float64)
    p0, p1, p2 = v[faces[:, 0]], v[faces[:, 1]], v[faces[:, 2]]
    centre = np.stack([np.bincount(comp, weights=p0[:, k], minlength=n_comp) for k in range(3)], 1)
    centre /= np.maximum(np.bincount(comp, minlength=n_comp), 1)[:, None]
    c = centre[comp]
    signed = np.einsum("ij,ij->i", p0 - c, np.cross(p1 - c, p2 - c))
    inside_out = np.bincount(comp, weights=signed, minlength=n_comp) < 0
    turn = inside_out[comp]
    faces[turn] = faces[turn][:, ::-1]
    return mesh.with_geometry(mesh.vertices, faces)
