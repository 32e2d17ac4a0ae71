"""Marching cubes against analytic shapes, scikit-image, and the watertightness it promises."""

from __future__ import annotations

import numpy as np
import pytest

from tests.surface.surface_fields import (
    crossing_distances,
    directed_edges_unique,
    edge_counts,
    ellipsoid_area,
    ellipsoid_field,
    welded_inner_edges,
)
from volumen.core import Volume
from volumen.surface import marching_cubes, vertex_normals
from volumen.surface._check import welded
from volumen.surface._mc_kernel import T_MIN


def test_sphere_area_volume_within_1_percent(sphere_mesh):
    r = 20.0
    assert sphere_mesh.area() == pytest.approx(4 * np.pi * r**2, rel=0.01)
    assert sphere_mesh.volume() == pytest.approx(4 / 3 * np.pi * r**3, rel=0.01)


@pytest.mark.parametrize("spacing", [(1.0, 1.0, 1.0), (1.6, 0.9, 1.2)])
def test_ellipsoid_area_volume_within_1_percent(spacing):
    a, b, c = 20.0, 15.0, 12.0  # mm along x, y, z
    shape = tuple(int(np.ceil(2 * s / d)) + 6 for s, d in zip((c, b, a), spacing, strict=True))
    mesh = marching_cubes(ellipsoid_field(shape, (a, b, c), spacing), 0.0)
    assert mesh.area() == pytest.approx(ellipsoid_area(a, b, c), rel=0.01)
    assert mesh.volume() == pytest.approx(4 / 3 * np.pi * a * b * c, rel=0.01)
    # and the vertices sit on the ellipsoid: |q - 1| small (0.05 of a voxel relative)
    centre = np.array([(shape[2] - 1) * spacing[2] / 2 + 0.31, (shape[1] - 1) * spacing[1] / 2 - 0.17,
                       (shape[0] - 1) * spacing[0] / 2 + 0.23])
    q = np.sqrt((((mesh.vertices - centre) / np.array([a, b, c])) ** 2).sum(axis=1))
    assert np.abs(q - 1).max() < 0.01


def test_sphere_normals_point_outward(sphere_volume, sphere_mesh):
    radial = sphere_mesh.vertices - sphere_volume.meta["centre_mm"]
    radial /= np.linalg.norm(radial, axis=1, keepdims=True)
    dots = (radial * sphere_mesh.normals).sum(axis=1)
    assert np.mean(dots > 0.9) >= 0.99
    assert np.allclose(np.linalg.norm(sphere_mesh.normals, axis=1), 1.0, atol=1e-5)


def test_closed_sphere_is_watertight_and_consistently_wound(sphere_mesh):
    assert set(edge_counts(sphere_mesh.faces).tolist()) == {2}
    assert directed_edges_unique(sphere_mesh.faces)
    # Euler characteristic of a sphere: V - E + F = 2
    e = len(edge_counts(sphere_mesh.faces))
    assert sphere_mesh.n_vertices - e + sphere_mesh.n_faces == 2


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("sigma", [0.0, 0.7])
def test_noise_is_watertight_including_ambiguous_cases(seed, sigma):
    from scipy import ndimage

    rng = np.random.default_rng(seed)
    noise = rng.random((24, 24, 24)).astype(np.float32)
    if sigma:
        noise = ndimage.gaussian_filter(noise, sigma)
    for level in np.quantile(noise, [0.3, 0.5, 0.7]):
        vol = np.pad(noise, 1, constant_values=noise.min() - 1.0)  # closes every surface
        mesh = marching_cubes(vol, float(level))
        assert mesh.n_faces > 100
        counts = edge_counts(mesh.faces)
        assert counts.min() == 2 and counts.max() == 2, f"edges shared by {np.unique(counts)} triangles"
        assert directed_edges_unique(mesh.faces)
        assert len(welded(mesh.vertices)[1]) == mesh.n_vertices, "duplicate vertices"
        f = mesh.faces
        assert not np.any((f[:, 0] == f[:, 1]) | (f[:, 1] == f[:, 2]) | (f[:, 0] == f[:, 2]))
        assert mesh.volume() > 0


def test_whole_values_at_a_whole_level_give_a_mesh_closed_when_welded_by_position():
    """Samples equal to the level (phantom "terraces": a fifth of them, with saddles between lumps above and below
    the level) would put every crossing of their edges on their own point, were vertices placed on grid points:
    3,970 triangles collapsed and 11 edges had four triangles once corners were joined by position, as an STL
    reader joins them.
    Kept ``T_MIN`` voxel off the grid points, every vertex has a position of its own: nothing collapses and every
    edge away from the border has two triangles; the area is scikit-image's within 0.5 %."""
    skimage_measure = pytest.importorskip("skimage.measure")
    from volumen.data import phantom

    vol = phantom("terraces")
    assert vol.meta["truth"]["at_level"] > 0.15
    mesh = marching_cubes(vol, 300.0)
    counts, collapsed = welded_inner_edges(mesh, vol.shape)
    assert collapsed == 0 and len(counts) > 5000 and np.all(counts == 2), np.bincount(counts)
    v, f, _, _ = skimage_measure.marching_cubes(vol.data.astype(np.float32), 300.0, spacing=vol.spacing)
    assert mesh.area() == pytest.approx(skimage_measure.mesh_surface_area(v, f), rel=0.005)


def _hausdorff(a: np.ndarray, b: np.ndarray) -> float:
    from scipy.spatial import cKDTree

    return max(cKDTree(b).query(a)[0].max(), cKDTree(a).query(b)[0].max())


def test_vertices_agree_with_scikit_image_on_a_smooth_field():
    skimage_measure = pytest.importorskip("skimage.measure")
    n = 40
    g = np.linspace(0, 2 * np.pi, n, dtype=np.float32)
    z, y, x = g[:, None, None], g[None, :, None] * 1.3, g[None, None, :] * 0.8
    vol = np.sin(x) * np.cos(y) + np.sin(y) * np.cos(z) + np.sin(z) * np.cos(x)
    level = 0.1
    ours = marching_cubes(vol, level)
    verts, faces, _, _ = skimage_measure.marching_cubes(vol, level)
    assert _hausdorff(ours.voxel_vertices[:, ::-1], verts) < 0.05  # voxels; skimage is [z, y, x]
    assert abs(ours.n_faces - len(faces)) <= 0.01 * len(faces)


def test_edge_vertices_equal_scikit_image_on_noise():
    """On noise both add a few vertices inside ambiguous cubes; the edge crossings must match (to 1e-4 voxel, and
    to ``T_MIN`` where scikit-image's are closer than that to a grid point)."""
    skimage_measure = pytest.importorskip("skimage.measure")
    vol = np.random.default_rng(5).random((20, 20, 20)).astype(np.float32)
    ours = marching_cubes(vol, 0.5).voxel_vertices[:, ::-1]
    theirs = skimage_measure.marching_cubes(vol, 0.5)[0]

    def on_edges(v):
        return v[(np.abs(v - np.round(v)) < 1e-6).sum(axis=1) >= 2]

    a, b = on_edges(ours), on_edges(theirs)
    assert len(a) == len(b)
    elsewhere, near = crossing_distances(a, b)
    assert elsewhere < 1e-4 and near < T_MIN + 1e-5


def test_world_coordinates_follow_an_oblique_flipped_affine(sphere_volume):
    """Vertices = affine @ voxel vertices; a left-handed affine keeps faces and normals outward."""
    c, s = np.cos(0.4), np.sin(0.4)
    rot = np.array([[-c, -s, 0], [s, -c, 0], [0, 0, 1.0]]) @ np.diag([-1.0, 1.0, 1.0])  # det = -1
    aff = np.eye(4)
    aff[:3, :3] = rot @ np.diag([0.8, 0.8, 1.5])
    aff[:3, 3] = [10.0, -20.0, 30.0]
    vol = Volume(sphere_volume.data, spacing=(1.5, 0.8, 0.8), affine=aff)
    mesh = marching_cubes(vol, 0.0)
    assert np.allclose(mesh.vertices, vol.index_to_world(mesh.voxel_vertices), atol=1e-4)
    assert mesh.volume() > 0
    radial = mesh.vertices - mesh.vertices.mean(axis=0)
    assert np.all((radial * mesh.normals).sum(axis=1) > 0)  # outward on this convex shape
    # gradient normals agree with the faces' geometry in world space
    dots = (vertex_normals(mesh.vertices, mesh.faces) * mesh.normals).sum(axis=1)
    assert np.mean(dots > 0.99) >= 0.99


def test_mask_and_step(sphere_volume, sphere_mesh):
    mask = np.zeros(sphere_volume.shape, bool)
    mask[:, :, :24] = True  # cubes with x < 24
    half = marching_cubes(sphere_volume, 0.0, mask=mask)
    assert half.voxel_vertices[:, 0].max() <= 24.0
    assert half.area() == pytest.approx(sphere_mesh.area() / 2, rel=0.02)
    assert set(np.unique(half.faces)) == set(range(half.n_vertices))  # no unused vertices
    coarse = marching_cubes(sphere_volume, 0.0, step=2)
    assert coarse.area() == pytest.approx(4 * np.pi * 400, rel=0.02)
    assert np.allclose(coarse.vertices, sphere_volume.index_to_world(coarse.voxel_vertices), atol=1e-4)


def test_boolean_mask_defaults_to_level_half():
    m = np.zeros((12, 12, 12), bool)
    m[3:9, 3:9, 3:9] = True
    mesh = marching_cubes(m)
    assert mesh.meta["level"] == 0.5
    # a cube of 6 voxels a side at level 0.5: six flat 5x5 faces, twelve 45-degree bevels
    # 5 long and 0.5 * sqrt(2) wide, eight corner triangles with sides 0.5 * sqrt(2)
    area = 6 * 25 + 12 * 5 * 0.5 * np.sqrt(2) + 8 * np.sqrt(3) / 4 * 0.5
    assert mesh.area() == pytest.approx(area, rel=1e-6)
    assert set(edge_counts(mesh.faces).tolist()) == {2}


def test_bad_input_raises_clear_errors(sphere_volume):
    with pytest.raises(ValueError, match="outside the data range"):
        marching_cubes(sphere_volume, 1e6)
    bad = sphere_volume.data.copy()
    bad[3, 3, 3] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        marching_cubes(bad, 0.0)
    with pytest.raises(ValueError, match="3-D"):
        marching_cubes(np.zeros((4, 4)), 0.0)
    with pytest.raises(ValueError, match="spacing"):
        marching_cubes(sphere_volume, 0.0, spacing=(1, 1, 1))
    with pytest.raises(ValueError, match="step"):
        marching_cubes(sphere_volume, 0.0, step=0)
