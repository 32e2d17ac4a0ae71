"""The Mesh: an indexed triangle surface in world RAS+ millimetres."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["Mesh", "vertex_normals"]


@dataclass(eq=False)
class Mesh:
    """An indexed triangle mesh.

    Parameters
    ----------
    vertices : (N, 3) float32, mm
        Vertex positions ``(x, y, z)`` in world RAS+ millimetres.
    faces : (M, 3) int32
        Vertex indices of each triangle, counter-clockwise seen from outside, so the
        right-hand normal points outward (toward lower values for an isosurface).
    normals : (N, 3) float32, optional
        Unit outward vertex normals in world space. Computed from the faces when not given.
    voxel_vertices : (N, 3) float32, optional
        The vertices as fractional voxel indices ``(i, j, k)`` = (column, row, slice) of the
        volume they came from; None once the geometry no longer matches (after smoothing).
    meta : dict
        Free-form facts: the iso level, the source volume's name, timings.
    """

    vertices: np.ndarray
    faces: np.ndarray
    normals: np.ndarray | None = None
    voxel_vertices: np.ndarray | None = None
    meta: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        v = np.ascontiguousarray(self.vertices, dtype=np.float32)
        f = np.asarray(self.faces)
        if v.ndim != 2 or v.shape[1] != 3:
            raise ValueError(f"vertices must be (N, 3), got shape {v.shape}")
        if f.size == 0:
            f = f.reshape(0, 3)
        if f.ndim != 2 or f.shape[1] != 3:
            raise ValueError(f"faces must be (M, 3), got shape {f.shape}")
        if f.dtype.kind not in "iu":
            raise ValueError(f"faces must hold integer vertex indices, got dtype {f.dtype}")
        if f.size and (f.min() < 0 or f.max() >= len(v)):
            raise ValueError(f"faces index vertices outside 0..{len(v) - 1}")
        self.vertices = v
        self.faces = np.ascontiguousarray(f, dtype=np.int32 if len(v) < 2**31 else np.int64)
        if self.normals is None:
            self.normals = vertex_normals(self.vertices, self.faces)
        else:
            self.normals = np.ascontiguousarray(self.normals, dtype=np.float32)
            if self.normals.shape != v.shape:
                raise ValueError(f"normals shape {self.normals.shape} differs from vertices {v.shape}")
        if self.voxel_vertices is not None:
            self.voxel_vertices = np.ascontiguousarray(self.voxel_vertices, dtype=np.float32)
            if self.voxel_vertices.shape != v.shape:
                raise ValueError("voxel_vertices must have the vertices' shape")
        self.meta = dict(self.meta)

    @property
    def n_vertices(self) -> int:
        return int(len(self.vertices))

    @property
    def n_faces(self) -> int:
        return int(len(self.faces))

    def area(self) -> float:
        """Surface area in mm^2."""
        from ._measure import surface_area

        return surface_area(self)

    def volume(self) -> float:
        """Enclosed volume in mm^3 (divergence theorem; positive for outward-facing closed meshes)."""
        from ._measure import enclosed_volume

        return enclosed_volume(self)

    def with_geometry(self, vertices: np.ndarray, faces: np.ndarray | None = None,
                      normals: np.ndarray | None = None, **meta) -> Mesh:
        """A new mesh with other vertices (and faces); normals recomputed unless given."""
        return Mesh(vertices, self.faces if faces is None else faces, normals,
                    meta={**self.meta, **meta})

    def _repr_png_(self) -> bytes:
        """Notebook display: a shaded thumbnail drawn without OpenGL (``volumen.notebook.pictures``)."""
        from ..core._repr import picture

        return picture("mesh_png", self)

    def __repr__(self) -> str:
        return f"Mesh({self.n_vertices} vertices, {self.n_faces} triangles)"


def vertex_normals(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Unit vertex normals ``(N, 3)`` float32: area-weighted sums of the faces' right-hand normals.

    Vertices used by no face get a zero normal.
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    if len(f) == 0:
        return np.zeros((len(v), 3), np.float32)
    fn = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])  # length = 2 * area
    out = np.zeros((len(v), 3))
    idx = f.ravel()
    for a in range(3):
        out[:, a] = np.bincount(idx, weights=np.repeat(fn[:, a], 3), minlength=len(v))
    norm = np.linalg.norm(out, axis=1, keepdims=True)
    np.divide(out, norm, out=out, where=norm > 0)
    return out.astype(np.float32)
