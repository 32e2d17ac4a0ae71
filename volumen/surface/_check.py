"""Is a mesh watertight? Open and non-manifold edges, pieces and genus, as a 3-D printer's slicer sees them.

An STL file holds triangles, not shared vertices: a reader joins corners at the same position. So the check
first welds vertices at equal positions and drops the triangles that collapse (two corners on one point: a mesh
whose vertices share positions, as marching cubes' did on grid points equal to the level before it kept them
``_mc_kernel.T_MIN`` off), then counts each edge's triangles: 1 is an open edge (a hole or the volume's
border), more than 2 a non-manifold edge. On a closed
2-manifold the Euler characteristic ``V - E + F`` gives the genus: ``(2 * pieces - chi) / 2`` (0 for each
sphere-like piece, 1 for a torus).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from ._mesh import Mesh
from ._mesh_components import mesh_components

__all__ = ["MeshCheck", "check_mesh"]


@dataclass(frozen=True)
class MeshCheck:
    """What :func:`check_mesh` found (counts after welding equal positions)."""

    triangles: int          #: triangles left after welding (collapsed ones dropped)
    collapsed: int          #: triangles with two corners on one point, dropped
    edges: int              #: distinct edges
    open_edges: int         #: edges of one triangle (holes, the volume's border)
    nonmanifold_edges: int  #: edges of three or more triangles
    pieces: int             #: connected pieces
    genus: int | None       #: sum of the pieces' genus; None unless closed and 2-manifold

    @property
    def closed(self) -> bool:
        """Every edge has exactly two triangles."""
        return self.open_edges == 0 and self.nonmanifold_edges == 0

    def line(self) -> str:
        """One line for the command line."""
        state = "closed" if self.closed else "open"
        genus = "" if self.genus is None else f", genus {self.genus}"
        return (f"{state}: {self.open_edges} open edges, {self.nonmanifold_edges} non-manifold edges of "
                f"{self.edges}, {self.pieces} pieces{genus}, {self.collapsed} collapsed triangles dropped")

    def to_dict(self) -> dict:
        return asdict(self) | {"closed": self.closed}


def check_mesh(mesh: Mesh) -> MeshCheck:
    """Open and non-manifold edges, pieces and genus of ``mesh`` with equal positions welded (module docstring)."""
    f = np.asarray(mesh.faces, np.int64).reshape(-1, 3)
    f = welded(mesh.vertices)[0][f]
    ok = (f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 2] != f[:, 0])
    f = f[ok]
    used, f = np.unique(f, return_inverse=True)
    f = f.reshape(-1, 3)
    _, count = np.unique(edge_keys(f, len(used)), return_counts=True)
    open_, over = int((count == 1).sum()), int((count > 2).sum())
    corners = np.zeros((len(used), 3), np.float32)  # positions do not matter for the pieces
    pieces = mesh_components(Mesh(corners, f, normals=corners))[0] if len(f) else 0
    genus = None
    if open_ == 0 and over == 0 and len(f):
        chi = len(used) - len(count) + len(f)
        genus = (2 * pieces - chi) // 2
    return MeshCheck(len(f), int((~ok).sum()), len(count), open_, over, pieces, genus)


def welded(vertices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Vertices joined by position: ``(label, first)``, per vertex the number of its position (0 .. P-1) and per
    position its first vertex in sort order. Positions are compared by their float32 bits (``+ 0.0`` makes -0.0
    the 0.0 it equals): a sort of two integer keys, a fifth of the time of ``np.unique(axis=0)``."""
    b = np.ascontiguousarray(np.asarray(vertices, np.float32) + np.float32(0.0)).view(np.uint32).astype(np.uint64)
    xy = (b[:, 0] << np.uint64(32)) | b[:, 1]
    order = np.lexsort((b[:, 2], xy))
    new = np.ones(len(order), np.bool_)
    new[1:] = (xy[order[1:]] != xy[order[:-1]]) | (b[order[1:], 2] != b[order[:-1], 2])
    label = np.empty(len(order), np.int64)
    label[order] = np.cumsum(new) - 1
    return label, order[new]


def edge_keys(faces: np.ndarray, n_vertices: int) -> np.ndarray:
    """One int64 per triangle edge, ``a * n_vertices + b`` for its corners a < b: (3 M,), the triangles' first
    edges, then their second, then their third."""
    f = np.sort(np.asarray(faces, np.int64), axis=1)
    return np.concatenate([f[:, 0] * n_vertices + f[:, 1], f[:, 1] * n_vertices + f[:, 2],
                           f[:, 0] * n_vertices + f[:, 2]])
