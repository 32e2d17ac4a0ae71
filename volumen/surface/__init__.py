"""volumen.surface: marching cubes, mesh processing and mesh files (docs/design.md section 1).

Meshes are :class:`Mesh` objects: float32 vertices in world RAS+ millimetres, int32
triangles wound counter-clockwise seen from outside, unit outward vertex normals.
Nothing heavy is imported here: Numba, SciPy and trimesh load on first use.
"""

from ._check import MeshCheck, check_mesh
from ._decimate import decimate
from ._extract import extract_mesh, is_mask
from ._files import MESH_FORMATS, read_mesh, write_mesh
from ._label_meshes import SCENE_FORMATS, label_areas, label_meshes, write_label_scene
from ._marching_cubes import marching_cubes
from ._measure import enclosed_volume, surface_area
from ._mesh import Mesh, vertex_normals
from ._mesh_components import largest_component, mesh_components, submesh
from ._orient import orient_outward
from ._smooth import laplacian_smooth, taubin_smooth

__all__ = [
    "Mesh",
    "marching_cubes",
    "extract_mesh",
    "is_mask",
    "vertex_normals",
    "surface_area",
    "enclosed_volume",
    "check_mesh",
    "MeshCheck",
    "mesh_components",
    "largest_component",
    "submesh",
    "orient_outward",
    "taubin_smooth",
    "laplacian_smooth",
    "decimate",
    "read_mesh",
    "write_mesh",
    "MESH_FORMATS",
    "label_meshes",
    "label_areas",
    "write_label_scene",
    "SCENE_FORMATS",
]
