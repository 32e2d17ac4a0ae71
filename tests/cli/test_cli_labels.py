"""``--labels`` on the command line: volumes and areas (info), coloured scenes (mesh), named outlines (slices).

Numbers against analytic shapes: a ball label of radius 12 mm (1 mm voxels) has its voxel volume exactly and
its smoothed surface area within 2 % of 4 pi r^2. About 10 s (marching cubes compile once).
"""

from __future__ import annotations

import json

import nibabel as nib
import numpy as np
import pytest

from volumen.cli import main
from volumen.data import organ_phantom

R = 12.0


@pytest.fixture(scope="module")
def ball(tmp_path_factory):
    """A scan and a label map (a ball 'ball', a box 'box') on the same 1 mm grid, NIfTI, names beside it."""
    d = tmp_path_factory.mktemp("ball")
    z, y, x = np.mgrid[:40, :40, :40]
    lab = (((x - 19.5) ** 2 + (y - 19.5) ** 2 + (z - 19.5) ** 2) <= R * R).astype(np.uint8)
    lab[2:8, 2:8, 2:10] = 2
    scan = np.where(lab > 0, 60, -100).astype(np.int16)
    for name, arr in (("ct", scan), ("seg", lab)):
        nib.save(nib.Nifti1Image(arr.transpose(2, 1, 0), np.eye(4)), str(d / f"{name}.nii.gz"))
    (d / "seg.csv").write_text("value,name,r,g,b\n1,ball,255,0,0\n2,box,0,0,255\n")
    return d, lab


def test_info_labels_volumes_and_areas(ball, capsys):
    d, lab = ball
    assert main(["info", str(d / "ct.nii.gz"), "--labels", str(d / "seg.nii.gz"), "--json"]) == 0
    rows = {r["name"]: r for r in json.loads(capsys.readouterr().out)["structures"]}
    assert rows["ball"]["volume_ml"] == pytest.approx((lab == 1).sum() / 1000.0, abs=1e-3)
    assert rows["box"]["volume_ml"] == pytest.approx(6 * 6 * 8 / 1000.0, abs=1e-3)
    sphere = 4 * np.pi * R * R
    assert abs(rows["ball"]["area_mm2"] - sphere) / sphere < 0.02


def test_mesh_labels_writes_a_coloured_scene(ball, tmp_path, capsys):
    import trimesh

    d, _ = ball
    out = tmp_path / "organs.glb"
    assert main(["mesh", str(d / "ct.nii.gz"), "--labels", str(d / "seg.nii.gz"), "-o", str(out)]) == 0
    scene = trimesh.load(str(out))
    assert set(scene.geometry) == {"ball", "box"}
    ball_mesh = scene.geometry["ball"]
    assert tuple(ball_mesh.visual.vertex_colors[0][:3]) == (255, 0, 0)
    assert abs(ball_mesh.area - 4 * np.pi * R * R) / (4 * np.pi * R * R) < 0.02


def test_mesh_show_keeps_the_named_structures(tmp_path, capsys):
    import trimesh

    out = tmp_path / "o.glb"
    assert main(["mesh", "phantom:organs?size=40", "--labels", "phantom:organs?size=40", "--show",
                 "liver,aorta", "-o", str(out)]) == 0
    assert set(trimesh.load(str(out)).geometry) == {"liver", "aorta"}
    assert main(["mesh", "phantom:organs?size=40", "--labels", "phantom:organs?size=40", "--show",
                 "heart", "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert "heart" in err and "liver" in err and "Traceback" not in err


def test_slices_outline_each_structure_in_its_colour(tmp_path, capsys):
    """The axial overlay: the liver's outline pixels carry the liver's colour, and lie where the phantom's
    label slice changes (every outline pixel is a boundary pixel of the label slice)."""
    from PIL import Image

    from volumen.core import label_slice

    vol, labels = organ_phantom(96)
    assert main(["slices", "phantom:organs?size=96", "--labels", "phantom:organs?size=96", "-o",
                 str(tmp_path), "--size", "0"]) == 0  # one pixel per voxel, as label_slice
    img = np.asarray(Image.open(next(tmp_path.glob("*_labels_axial.png"))))
    lab = label_slice(labels, "axial", world=vol.center)
    col = np.round(np.asarray(labels.colors[1]) ** (1 / 2.2) * 255).astype(int)
    hit = np.all(np.abs(img.astype(int) - col) <= 1, axis=2)
    liver = lab == 1
    inner = liver.copy()
    inner[1:-1, 1:-1] = liver[1:-1, 1:-1] & liver[:-2, 1:-1] & liver[2:, 1:-1] & liver[1:-1, :-2] & liver[1:-1, 2:]
    boundary = liver & ~inner
    assert hit[boundary].mean() > 0.8  # names written over the outline hide a few pixels
    assert not hit[inner].any()
