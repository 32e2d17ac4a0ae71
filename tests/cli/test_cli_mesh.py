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



def test_mesh_with_no_level_takes_the_one_the_3d_views_start_with_and_says_so(tmp_path, capsys):
    """No ``--iso`` and no ``--mask``: a CT is meshed at bone (``core.default_iso``: 300 HU), an MRI at the middle
    of its display range, a 0/1 mask at its boundary; the output line names the level and why. Before, the
    command stopped with an error."""
    import volumen
    from volumen.core import default_iso
    from volumen.data import phantom
    from volumen.surface import extract_mesh, read_mesh

    for name, says in (("head", "chosen for a CT: bone"), ("mr_head", "chosen: the middle of the display range")):
        out = tmp_path / f"{name}.stl"
        assert main(["mesh", f"phantom:{name}?size=40", "-o", str(out), "--quiet", "--smooth", "0"]) == 0
        printed = capsys.readouterr().out
        level = default_iso(phantom(name, size=40))
        assert f"(level {level:g}, {says})" in printed, printed
        assert read_mesh(out).n_faces == extract_mesh(phantom(name, size=40), iso=level, smooth_iterations=0).n_faces
    z, y, x = np.indices((20, 20, 20))
    ball = volumen.Volume(((x - 10) ** 2 + (y - 10) ** 2 + (z - 10) ** 2 < 36).astype(np.uint8))
    volumen.save(ball, tmp_path / "ball.nii.gz")
    assert main(["mesh", str(tmp_path / "ball.nii.gz"), "-o", str(tmp_path / "ball.stl"), "--quiet"]) == 0
    assert "(level 0.5, chosen: the mask's boundary)" in capsys.readouterr().out
