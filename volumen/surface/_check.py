"""Is a mesh watertight? Open and non-manifold edges, pieces and genus, as a 3-D printer's slicer sees them.

An STL file holds triangles, not shared vertices: a reader joins corners at the same position. So the check
first welds vertices at equal positions and drops the triangles that collapse (two corners on one point:
marching cubes puts a vertex on a grid point where a value equals the level exactly), then counts each edge's
triangles: 1 is an open edge (a hole or the volume's border), more than 2 a non-manifold edge. On a closed
2-manifold the Euler characteristic ``V - E + F`` gives the genus: ``(2 * pieces - chi) / 2`` (0 for each
sphere-like piece, 1 for a torus).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from ._components import mesh_components
from ._mesh import Mesh

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
    v = np.asarray(mesh.vertices, np.float64)
    f = np.asarray(mesh.faces, np.int64)
    _, weld = np.unique(v, axis=0, return_inverse=True)
    f = weld.reshape(-1)[f] if len(f) else f.reshape(0, 3)
    ok = (f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 2] != f[:, 0])
    f = f[ok]
    used, f = np.unique(f, return_inverse=True)
    f = f.reshape(-1, 3)
    e = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    _, count = np.unique(e, axis=0, return_counts=True)
    open_, over = int((count == 1).sum()), int((count > 2).sum())
    corners = np.zeros((len(used), 3), np.float32)  # positions do not matter for the pieces
    pieces = mesh_components(Mesh(corners, f, normals=corners))[0] if len(f) else 0
    genus = None
    if open_ == 0 and over == 0 and len(f):
        chi = len(used) - len(count) + len(f)
        genus = (2 * pieces - chi) // 2
    return MeshCheck(len(f), int((~ok).sum()), len(count), open_, over, pieces, genus)
