"""Mesh files: binary STL, OBJ and PLY through trimesh, read back too."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ._mesh import Mesh

__all__ = ["write_mesh", "read_mesh", "MESH_FORMATS"]

MESH_FORMATS = {".stl": "stl", ".obj": "obj", ".ply": "ply"}


def _format(path: Path) -> str:
    from ..errors import UnknownFormatError

    fmt = MESH_FORMATS.get(path.suffix.lower())
    if fmt is None:
        raise UnknownFormatError(path, f"unknown mesh format {path.suffix!r}; choose one of {sorted(MESH_FORMATS)}")
    return fmt


def write_mesh(mesh: Mesh, path) -> Path:
    """Write a mesh as binary STL, OBJ or binary PLY, chosen by the file extension.

    Vertices are world RAS+ millimetres. STL stores three corners per triangle and a
    face normal (no shared vertices); OBJ and PLY keep the indexed vertices and the
    vertex normals.
    """
    import trimesh

    path = Path(path)
    fmt = _format(path)
    tm = trimesh.Trimesh(vertices=mesh.vertices, faces=mesh.faces, vertex_normals=mesh.normals, process=False)
    if fmt == "ply":
        data = trimesh.exchange.ply.export_ply(tm, encoding="binary", vertex_normal=True)
    elif fmt == "obj":
        data = trimesh.exchange.obj.export_obj(tm, include_normals=True, digits=9, header=None)
    else:
        data = trimesh.exchange.stl.export_stl(tm)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(data if isinstance(data, bytes) else data.encode())
    except OSError as exc:
        from ..errors import VolumeWriteError

        raise VolumeWriteError(path, f"cannot write mesh: {exc.strerror or exc}") from exc
    return path


def read_mesh(path) -> Mesh:
    """Read an STL, OBJ or PLY file as a :class:`Mesh` (world mm as stored).

    STL triangles are re-indexed by merging corners with bit-identical coordinates, so
    a mesh written by :func:`write_mesh` comes back with its shared vertices.

    Raises
    ------
    volumen.errors.MissingPathError, UnknownFormatError, CorruptDataError
        When the file is missing, has an unknown extension or is not a readable triangle mesh.
    """
    import trimesh

    from ..errors import CorruptDataError, MissingPathError

    path = Path(path)
    fmt = _format(path)
    if not path.is_file():
        raise MissingPathError(path, "no such mesh file")
    try:
        tm = trimesh.load(path, file_type=fmt, process=False, force="mesh")
    except Exception as exc:  # trimesh raises many kinds
        raise CorruptDataError(path, f"cannot read mesh: {exc}") from exc
    if not isinstance(tm, trimesh.Trimesh) or len(tm.faces) == 0:
        raise CorruptDataError(path, "holds no triangles")
    vertices = np.asarray(tm.vertices, np.float32)
    faces = np.asarray(tm.faces, np.int64)
    if fmt == "stl":
        vertices, inverse = np.unique(vertices, axis=0, return_inverse=True)
        faces = inverse.reshape(-1)[faces]
    normals = None
    if fmt != "stl" and "vertex_normals" in tm._cache.cache:
        normals = np.asarray(tm.vertex_normals, np.float32)
    return Mesh(vertices, faces, normals, meta={"source": str(path)})
