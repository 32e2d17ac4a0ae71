"""`volumen mesh`: the written file holds the isosurface (its area against the sphere's), errors come first."""

from __future__ import annotations

import numpy as np

from volumen.cli import main


def test_mesh_of_the_sphere_phantom_has_the_sphere_area(tmp_path, capsys):
    """Sphere phantom radius 20 mm (1 mm voxels, +-1000 HU, partial volume): the 0 HU surface read back from
    the STL has the area 4 pi r^2 within 2% (smoothing off, so the mesh is the marching-cubes surface);
    ``--check`` finds it closed, one piece of genus 0."""
    from volumen.surface import read_mesh, surface_area

    out = tmp_path / "sphere.stl"
    assert main(["mesh", "phantom:sphere?radius=20&antialias=1", "--iso", "0", "--smooth", "0", "-o", str(out),
                 "--quiet", "--check"]) == 0
    mesh = read_mesh(out)
    area = surface_area(mesh)
    assert abs(area - 4 * np.pi * 20.0 ** 2) / (4 * np.pi * 20.0 ** 2) < 0.02, area
    printed = capsys.readouterr().out
    assert str(out) in printed
    assert "closed: 0 open edges, 0 non-manifold edges" in printed and "1 pieces, genus 0" in printed, printed


def test_mesh_rejects_an_unknown_suffix_before_any_work(tmp_path, capsys):
    assert main(["mesh", "phantom:sphere", "--iso", "0", "-o", str(tmp_path / "m.xyz")]) == 1
    err = capsys.readouterr().err
    assert ".stl" in err and "Traceback" not in err
