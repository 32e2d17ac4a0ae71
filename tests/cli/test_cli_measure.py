"""``volumen measure volumes``: a sphere's volume from its label map within 1 % of 4/3 pi r^3, printed and written
as CSV; a bad input is one line and writes nothing."""

from __future__ import annotations

import numpy as np

import volumen
from volumen.cli import main


def test_measure_volumes_of_a_sphere(tmp_path, capsys):
    spacing, r = (0.9, 0.7, 0.8), 15.0
    zyx = np.stack(np.meshgrid(*(np.arange(n) * s for n, s in zip((45, 60, 50), spacing, strict=True)),
                               indexing="ij"), -1)
    inside = ((zyx - (20.0, 21.0, 20.0)) ** 2).sum(-1) <= r**2
    volumen.save(volumen.Volume(inside.astype(np.uint8) * 2, spacing=spacing), tmp_path / "ball.nii.gz")
    assert main(["measure", "volumes", str(tmp_path / "ball.nii.gz"), "-o", str(tmp_path / "v.csv")]) == 0
    (line,) = capsys.readouterr().out.strip().splitlines()
    ml = float(line.split()[1])
    assert abs(ml - 4 / 3 * np.pi * r**3 / 1000) < 0.01 * 4 / 3 * np.pi * r**3 / 1000
    rows = (tmp_path / "v.csv").read_text().splitlines()
    assert rows[0].startswith("kind,label,value,unit") and rows[1].split(",")[3] == "ml"


def test_measure_volumes_of_a_missing_file_is_one_line(tmp_path, capsys):
    assert main(["measure", "volumes", str(tmp_path / "none.nii.gz"), "-o", str(tmp_path / "out" / "v.csv")]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("volumen measure: error: ") and "none.nii.gz" in err[0]
    assert not (tmp_path / "out").exists()
