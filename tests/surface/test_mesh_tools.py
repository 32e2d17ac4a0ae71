"""Mesh processing: measures, components, orientation, smoothing, decimation, files, extract_mesh."""

from __future__ import annotations

import numpy as np
import pytest

from tests.surface.surface_fields import directed_edges_unique, edge_counts, ellipsoid_field
from volumen.core import Volume
from volumen.surface import (
    Mesh,
    decimate,
    extract_mesh,
    laplacian_smooth,
    largest_component,
    marching_cubes,
    mesh_components,
    orient_outward,
    read_mesh,
    taubin_smooth,
    write_mesh,
)


def unit_cube() -> Mesh:
    v = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], float)
    f = np.array([[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4],
                  [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]])
    return Mesh(v, f)


def test_cube_area_and_volume_are_exact():
    cube = unit_cube()
    assert cube.area() == pytest.approx(6.0, abs=1e-9)
    assert cube.volume() == pytest.approx(1.0, abs=1e-9)
    flipped = Mesh(cube.vertices + 100.0, cube.faces[:, ::-1])  # inward faces, far from the origin
    assert flipped.volume() == pytest.approx(-1.0, abs=1e-6)


def test_largest_component_keeps_the_bigger_sphere():
    big = ellipsoid_field((40, 40, 64), (12.0, 12.0, 12.0), centre_mm=(20.0, 20.0, 19.5)).data
    small = ellipsoid_field((40, 40, 64), (6.0, 6.0, 6.0), centre_mm=(50.0, 20.0, 19.5)).data
    both = marching_cubes(np.maximum(big, small), 0.0)
    n, _ = mesh_components(both)
    assert n == 2
    kept = largest_component(both)
    alone = marching_cubes(big, 0.0)
    assert kept.n_faces == alone.n_faces
    assert kept.area() == pytest.approx(alone.area(), rel=1e-9)
    assert set(edge_counts(kept.faces).tolist()) == {2}


def test_orient_outward_repairs_flipped_faces(sphere_mesh):
    rng = np.random.default_rng(0)
    faces = sphere_mesh.faces.copy()
    flip = rng.random(len(faces)) < 0.5
    faces[flip] = faces[flip][:, ::-1]
    fixed = orient_outward(Mesh(sphere_mesh.vertices, faces))
    assert directed_edges_unique(fixed.faces)
    assert fixed.volume() == pytest.approx(sphere_mesh.volume(), rel=1e-9)
    inverted = orient_outward(Mesh(sphere_mesh.vertices, sphere_mesh.faces[:, ::-1]))
    assert np.array_equal(inverted.faces, sphere_mesh.faces)


def _rough_sphere(sphere_mesh, sphere_volume, amount=0.3):
    rng = np.random.default_rng(1)
    centre = sphere_volume.meta["centre_mm"]
    radial = sphere_mesh.vertices - centre
    radial /= np.linalg.norm(radial, axis=1, keepdims=True)
    bumps = rng.uniform(-amount, amount, len(radial))[:, None]
    return sphere_mesh.with_geometry(sphere_mesh.vertices + bumps * radial), centre


def test_taubin_keeps_volume_and_smooths_where_laplacian_shrinks(sphere_mesh, sphere_volume):
    rough, centre = _rough_sphere(sphere_mesh, sphere_volume)

    def roughness(m):
        return np.std(np.linalg.norm(m.vertices - centre, axis=1))

    taubin = taubin_smooth(rough, iterations=20)
    laplace = laplacian_smooth(rough, iterations=20)
    v0 = rough.volume()
    assert abs(taubin.volume() / v0 - 1) < 0.02  # volume within 2 %
    assert 1 - laplace.volume() / v0 > 3 * abs(taubin.volume() / v0 - 1)  # Laplacian shrinks more
    assert roughness(taubin) < 0.5 * roughness(rough)  # measured: 0.33


def test_decimation_hits_the_target_and_keeps_the_area(sphere_mesh):
    target = 3000
    small = decimate(sphere_mesh, target)
    assert abs(small.n_faces - target) <= 0.05 * target
    assert small.area() == pytest.approx(sphere_mesh.area(), rel=0.05)
    assert small.volume() == pytest.approx(sphere_mesh.volume(), rel=0.05)


@pytest.mark.parametrize("suffix", [".stl", ".obj", ".ply"])
def test_mesh_files_round_trip(sphere_mesh, tmp_path, suffix):
    path = write_mesh(sphere_mesh, tmp_path / f"sphere{suffix}")
    back = read_mesh(path)
    assert back.n_faces == sphere_mesh.n_faces
    assert back.n_vertices == sphere_mesh.n_vertices
    # same triangles with the same corner positions (vertex order may differ for STL)
    a = np.sort(sphere_mesh.vertices[sphere_mesh.faces].reshape(-1, 9), axis=0)
    b = np.sort(back.vertices[back.faces].reshape(-1, 9), axis=0)
    assert np.allclose(a, b, rtol=2 * np.finfo(np.float32).eps, atol=0)
    assert back.volume() == pytest.approx(sphere_mesh.volume(), rel=1e-6)  # winding kept


def test_unknown_and_missing_mesh_files_raise_typed_errors(tmp_path):
    from volumen.errors import MissingPathError, UnknownFormatError

    with pytest.raises(UnknownFormatError, match="choose one of"):
        write_mesh(unit_cube(), tmp_path / "cube.xyz")
    with pytest.raises(MissingPathError):
        read_mesh(tmp_path / "absent.stl")


def test_extract_mesh_from_a_mask_reports_progress_and_matches_the_sphere():
    vol = ellipsoid_field((48, 48, 48), (20.0, 20.0, 20.0))
    ct = Volume((vol.data * 50).astype(np.int16), spacing=vol.spacing)  # "HU", 50 per mm
    seen = []
    mesh = extract_mesh(ct, mask=ct.data > 0, smooth_iterations=20, target_triangles=4000,
                        largest_only=True, progress=seen.append)
    assert seen[0] == 0.0 and seen[-1] == 1.0 and seen == sorted(seen)
    assert abs(mesh.n_faces - 4000) <= 200
    assert mesh.area() == pytest.approx(4 * np.pi * 20**2, rel=0.03)
    assert mesh.volume() == pytest.approx(4 / 3 * np.pi * 20**3, rel=0.03)
    iso = extract_mesh(ct, iso=0.0, smooth_iterations=0)
    assert iso.area() == pytest.approx(4 * np.pi * 20**2, rel=0.01)
    with pytest.raises(ValueError, match="iso level"):
        extract_mesh(ct)
