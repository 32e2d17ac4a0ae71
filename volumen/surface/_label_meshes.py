"""Surfaces of the structures of a label map: one smoothed, decimated mesh each, areas, a coloured scene file.

Each structure is meshed on its bounding box (one voxel of margin) at level 0.5 of its
0/1 mask, then Taubin-smoothed (no shrinking) so the voxel steps go, and decimated when
asked. :func:`write_label_scene` writes the meshes with their colours as one glTF
(``.glb``), PLY or OBJ scene (trimesh).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..core import LabelMap, Volume
from ._extract import extract_mesh
from ._mesh import Mesh

__all__ = ["label_meshes", "label_areas", "write_label_scene", "SCENE_FORMATS"]

SCENE_FORMATS = (".glb", ".gltf", ".ply", ".obj")


def _box_volume(labels: LabelMap, value: int) -> Volume | None:
    m = labels.data == value
    idx = np.nonzero(m.any(axis=(1, 2)))[0], np.nonzero(m.any(axis=(0, 2)))[0], np.nonzero(m.any(axis=(0, 1)))[0]
    if any(len(i) == 0 for i in idx):
        return None
    lo = [max(int(i[0]) - 1, 0) for i in idx]
    hi = [min(int(i[-1]) + 2, n) for i, n in zip(idx, m.shape, strict=True)]
    sub = m[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]]
    sub = np.pad(sub, 1).view(np.uint8)  # closed surfaces where a structure touches the grid's edge
    shift = np.eye(4)
    shift[:3, 3] = [lo[2] - 1, lo[1] - 1, lo[0] - 1]  # (i, j, k)
    return Volume(sub, labels.spacing, labels.affine @ shift)


def label_meshes(labels: LabelMap, names=None, *, smooth_iterations: int = 10,
                 target_triangles: int | None = None) -> dict[int, Mesh]:
    """A mesh per structure (world RAS+ mm), keyed by label value.

    Parameters
    ----------
    labels : LabelMap
    names : iterable of str or int, optional
        The structures to mesh (all by default).
    smooth_iterations : int
        Taubin iterations (0: the raw marching-cubes steps).
    target_triangles : int, optional
        Decimate each mesh to about this many triangles.
    """
    values = labels.values if names is None else [labels.value_of(n) for n in names]
    out = {}
    for v in values:
        box = _box_volume(labels, v)
        if box is None:
            continue
        mesh = extract_mesh(box, smooth_iterations=smooth_iterations, target_triangles=target_triangles)
        mesh.meta["name"] = labels.names[v]
        out[v] = mesh
    return out


def label_areas(labels: LabelMap, smooth_iterations: int = 10) -> dict[int, float]:
    """Surface area of each structure in mm^2 (smoothed marching-cubes surface; 0 for an absent one)."""
    meshes = label_meshes(labels, smooth_iterations=smooth_iterations)
    return {v: (meshes[v].area() if v in meshes else 0.0) for v in labels.values}


def write_label_scene(meshes: dict[int, Mesh], labels: LabelMap, path) -> Path:
    """Write ``meshes`` (from :func:`label_meshes`) as one coloured scene; the suffix picks the format."""
    import trimesh

    path = Path(path)
    if path.suffix.lower() not in SCENE_FORMATS:
        raise ValueError(f"{path}: a labelled scene is written as {', '.join(SCENE_FORMATS)}")
    scene = trimesh.Scene()
    for v, mesh in meshes.items():
        rgb = np.clip(np.asarray(labels.colors[v]) ** (1 / 2.2), 0, 1)  # linear -> sRGB for the file
        rgba = np.r_[np.round(rgb * 255), 255].astype(np.uint8)
        tm = trimesh.Trimesh(mesh.vertices, mesh.faces, vertex_normals=mesh.normals, process=False)
        tm.visual = trimesh.visual.ColorVisuals(tm, vertex_colors=np.tile(rgba, (len(mesh.vertices), 1)))
        scene.add_geometry(tm, node_name=labels.names[v], geom_name=labels.names[v])
    if path.suffix.lower() in (".ply", ".obj"):
        trimesh.util.concatenate(list(scene.geometry.values())).export(str(path))
    else:
        scene.export(str(path))
    return path
