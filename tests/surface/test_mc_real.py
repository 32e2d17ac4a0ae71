"""Marching cubes on a real CT (the VMTK aorta CTA) against scikit-image and VTK, and the kernel's own paths:
native dtypes against a float32 copy, parallel runs against one serial run."""

from __future__ import annotations

import numpy as np
import pytest

from tests.surface.surface_fields import crossing_distances, welded_inner_edges
from volumen.surface import marching_cubes

#: scanner units of the aorta scan: contrast vessels down to the smallest fragments, and the lumen wall
LEVELS = (800.0, 1100.0)


@pytest.fixture(scope="module")
def aorta():
    """The VMTK aorta rounded to int16 (157 x 393 x 34 voxels), or a skip naming where it was looked for."""
    from volumen.bench._mesh import aorta_path
    from volumen.io import load

    path = aorta_path()
    if path is None:
        pytest.skip("VMTK aorta not found: set VOLUMEN_SHARED_DATA to the folder holding vmtk-aorta/")
    vol = load(path)
    vol.data = np.rint(vol.data).astype(np.int16)
    return vol


def _on_edges(v: np.ndarray) -> np.ndarray:
    """Vertices on grid edges (two integer coordinates), sorted: the ones both extractors must share."""
    e = v[(np.abs(v - np.round(v)) < 1e-6).sum(axis=1) >= 2]
    return e[np.lexsort(e.T)]


@pytest.mark.parametrize("level", LEVELS)
def test_aorta_edge_vertices_equal_scikit_image(aorta, level):
    """Same crossed edges as scikit-image (Lewiner), at the same places (1e-4 voxel; ``T_MIN`` where scikit-image
    puts a crossing on a grid point, as whole values at a whole level do); the triangle and vertex counts differ
    only by the few cubes each triangulates with an extra inside vertex (<= 0.5%)."""
    skimage_measure = pytest.importorskip("skimage.measure")
    from volumen.surface._mc_kernel import T_MIN

    ours = marching_cubes(aorta, level)
    verts, faces, _, _ = skimage_measure.marching_cubes(aorta.data.astype(np.float32), level)
    a, b = _on_edges(ours.voxel_vertices[:, ::-1]), _on_edges(verts)  # skimage is [z, y, x]
    assert len(a) == len(b) > 5000
    elsewhere, near = crossing_distances(a, b)
    assert elsewhere < 1e-4 and near < T_MIN + 1e-5
    assert abs(ours.n_vertices - len(verts)) <= 0.005 * len(verts)
    assert abs(ours.n_faces - len(faces)) <= 0.005 * len(faces)


@pytest.mark.parametrize("level", LEVELS)
def test_aorta_area_equals_vtk_flying_edges(aorta, level):
    """Surface area within 0.5% of vtkFlyingEdges3D's on the same array and spacing."""
    vtk = pytest.importorskip("vtk")
    from volumen.surface._bench import _vtk_flying_edges

    fe = _vtk_flying_edges(aorta.data, level, 1, aorta.spacing)
    fe()
    props = vtk.vtkMassProperties()
    props.SetInputData(fe.output())
    props.Update()
    ours = marching_cubes(aorta, level, voxel_coordinates=False)
    assert ours.area() == pytest.approx(props.GetSurfaceArea(), rel=0.005)
    assert abs(ours.n_faces - fe.output().GetNumberOfCells()) <= 0.005 * ours.n_faces


@pytest.mark.parametrize("dtype", [np.int16, np.uint16, np.uint8, np.bool_])
def test_native_dtypes_give_the_float32_mesh_exactly(aorta, dtype):
    """Read as they are (no converted copy), integer and boolean data give the mesh of their float32 copy."""
    data = aorta.data[:, :200, :]
    scale = 10 if dtype is np.uint8 else 1  # the scan's 0..2570 into 0..257
    data = data > 1100 if dtype is np.bool_ else np.clip(data // scale, 0, np.iinfo(dtype).max).astype(dtype)
    level = 0.5 if dtype is np.bool_ else 1100.0 / scale
    a = marching_cubes(data, level, spacing=aorta.spacing)
    b = marching_cubes(data.astype(np.float32), level, spacing=aorta.spacing)
    for name in ("vertices", "faces", "normals", "voxel_vertices"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name


def test_parallel_runs_give_the_serial_mesh_exactly(aorta, monkeypatch):
    """Rows split into runs of balanced cost (several per thread here) give the mesh of one serial run."""
    import numba

    from volumen.surface import _mc_rows

    serial = marching_cubes(aorta, LEVELS[0])
    monkeypatch.setattr(_mc_rows, "SERIAL_COST", 0)
    monkeypatch.setattr(numba, "get_num_threads", lambda: 5)
    runs = _mc_rows.balanced_runs(np.arange(100.0), 5)
    assert runs[0] == 0 and runs[-1] == 100 and np.all(np.diff(runs) > 0)
    parallel = marching_cubes(aorta, LEVELS[0])
    for name in ("vertices", "faces", "normals", "voxel_vertices"):
        assert np.array_equal(getattr(serial, name), getattr(parallel, name)), name


@pytest.mark.parametrize("level", (300.0, *LEVELS))
def test_aorta_mesh_is_closed_away_from_the_scan_border(aorta, level):
    """Integer CT values at an integer level put crossings on grid points: at 300 HU, with corners joined by
    position as an STL reader joins them, 18,804 triangles collapsed and 50 edges had four triangles before issue
    26's fix (800: 413 and 0, 1100: 225 and 0). Kept ``T_MIN`` voxel off grid points, nothing collapses and every
    edge away from the scan's border has two triangles; the area (mm^2) is scikit-image's within 0.5 %."""
    skimage_measure = pytest.importorskip("skimage.measure")
    mesh = marching_cubes(aorta, level)
    counts, collapsed = welded_inner_edges(mesh, aorta.shape)
    print(f"{len(counts)} edges away from the border, {collapsed} collapsed triangles")
    assert collapsed == 0 and len(counts) > 50_000 and np.all(counts == 2), np.bincount(counts)
    v, f, _, _ = skimage_measure.marching_cubes(aorta.data.astype(np.float32), level,
                                                spacing=tuple(float(s) for s in aorta.spacing))
    theirs = skimage_measure.mesh_surface_area(v, f)
    print(f"area {mesh.area():.0f} mm2, scikit-image {theirs:.0f} mm2 ({mesh.area() / theirs - 1:+.2%})")
    assert mesh.area() == pytest.approx(theirs, rel=0.005)


def test_mri_template_at_its_otsu_level_is_closed_with_the_area_of_scikit_image():
    """The MRI template (uint8, 316 x 370 x 301 voxels of 0.5 mm; every other sample, 1 mm, to cost a second) at
    the Otsu level of its head (of the non-zero voxels, as ``volumen bench mesh``; Otsu over all voxels is 0, the
    background's value): 0.7 % of the samples equal the level, which with vertices on grid points gives 97,320
    collapsed triangles and 88 edges of four triangles once welded by position (full size: 704,953 and 529). Kept
    off the grid points: none, and the area is scikit-image's (same step) within 0.5 %."""
    skimage = pytest.importorskip("skimage")
    from skimage.filters import threshold_otsu
    from skimage.measure import marching_cubes as sk_marching_cubes
    from skimage.measure import mesh_surface_area

    from volumen.data import sample
    from volumen.errors import SampleDataMissingError

    try:
        mri = sample("mni-brain")
    except SampleDataMissingError as exc:
        pytest.skip(str(exc))
    level = float(threshold_otsu(mri.data[mri.data > 0]))
    mesh = marching_cubes(mri, level, step=2)
    reach = tuple(2 * ((n - 1) // 2) + 1 for n in mri.shape)  # the samples' extent, in the voxels of the template
    counts, collapsed = welded_inner_edges(mesh, reach)
    assert collapsed == 0 and len(counts) > 1_000_000 and np.all(counts == 2), np.bincount(counts)
    v, f, _, _ = sk_marching_cubes(mri.data, level, spacing=tuple(float(s) for s in mri.spacing), step_size=2)
    theirs = mesh_surface_area(v, f)
    print(f"level {level:g}: area {mesh.area():.0f} mm2, scikit-image {skimage.__version__} {theirs:.0f} mm2")
    assert mesh.area() == pytest.approx(theirs, rel=0.005)
