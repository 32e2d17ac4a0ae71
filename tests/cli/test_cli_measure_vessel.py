"""``volumen measure vessel`` and ``volumen fly --report``: the report folder (profile.csv, report.json,
profile.png) on the stenosis phantom, from the points alone and from a lumen mask file, and the error contract
(one line, exit 1, nothing written)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from PIL import Image

import volumen
from volumen.cli import main
from volumen.core import Volume
from volumen.data import phantom

FILES = ["profile.csv", "profile.png", "report.json"]


@pytest.fixture(scope="module")
def vessel():
    return phantom("stenosis")


def _point(p) -> str:
    return ",".join(f"{v:.2f}" for v in p)


def _ends(vessel) -> list[str]:
    lm = vessel.meta["truth"]["landmarks"]
    return [f"--start={_point(lm['start'])}", f"--end={_point(lm['end'])}"]


def _check_report(folder, vessel) -> dict:
    """The three files are there and agree: the CSV's rows are the JSON table's, the picture is a picture; returns
    the JSON's summary, whose stenosis and maximum are the phantom's (5 points, 0.5 mm)."""
    assert sorted(p.name for p in folder.iterdir()) == FILES
    doc = json.loads((folder / "report.json").read_text(encoding="utf-8"))
    rows = (folder / "profile.csv").read_text(encoding="utf-8").splitlines()
    assert len(rows) - 1 == doc["summary"]["sections"] == len(doc["table"]["diameter_mm"])
    with Image.open(folder / "profile.png") as img:
        assert img.size[0] >= 800 and img.size[1] >= 600
    truth = vessel.meta["truth"]
    summary = doc["summary"]
    assert abs(summary["stenosis"]["percent"] - truth["stenosis"]) <= 5.0 and summary["stenosis"]["flagged"]
    assert abs(summary["maximum"]["diameter_mm"] - truth["max_diameter"]) <= 0.5 and summary["maximum"]["flagged"]
    return summary


def test_measure_vessel_with_a_lumen_mask_file(vessel, tmp_path, capsys):
    mask = vessel.meta["truth"]["vessel"].mask
    volumen.save(Volume(mask.astype(np.uint8), affine=vessel.affine), tmp_path / "lumen.nii.gz")
    out = tmp_path / "report"
    code = main(["measure", "vessel", "phantom:stenosis", *_ends(vessel), "--lumen-mask",
                 str(tmp_path / "lumen.nii.gz"), "-o", str(out)])
    printed = capsys.readouterr().out
    assert code == 0 and "stenosis" in printed and "FLAGGED" in printed
    assert _check_report(out, vessel)["source"] == "mask"


def test_fly_writes_the_report_of_its_flight(vessel, tmp_path, capsys):
    out = tmp_path / "report"
    code = main(["fly", "phantom:stenosis", *_ends(vessel), "-o", str(tmp_path / "f.gif"), "--frames", "2",
                 "--size", "16x16", "--no-progress", "--report", str(out)])
    capsys.readouterr()
    assert code == 0 and (tmp_path / "f.gif").exists()
    summary = _check_report(out, vessel)
    assert summary["source"] == "grown"


@pytest.mark.parametrize("argv, needle", [
    (["--start=40,40,0", "--end=-20.9,9.0,76.8"], "tissue, not a lumen; pass --range LO,HI or --threshold T"),
    (["--start=1,2", "--end=-20.9,9.0,76.8"], "3 comma-separated numbers"),
    (["--start=-18.4,-13.9,-75.3", "--end=-20.9,9.0,76.8", "--label", "3"], "--label needs --lumen-mask"),
    (["--start=-18.4,-13.9,-75.3", "--end=-20.9,9.0,76.8", "--lumen", "blood"], "'blood' is not one of"),
])
def test_measure_vessel_errors_are_one_line_and_write_nothing(tmp_path, capsys, argv, needle):
    out = tmp_path / "new" / "report"
    assert _exit_code(["measure", "vessel", "phantom:stenosis", *argv, "-o", str(out)]) == 1
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("volumen measure") and needle in err
    assert list(tmp_path.iterdir()) == []


def test_a_report_folder_that_is_a_file_is_refused(tmp_path, capsys):
    (tmp_path / "report").write_text("x")
    code = main(["measure", "vessel", "phantom:stenosis", "--start=0,0,0", "--end=1,1,1", "-o",
                 str(tmp_path / "report")])
    err = capsys.readouterr().err.strip()
    assert code == 1 and len(err.splitlines()) == 1 and "is a file" in err
    assert (tmp_path / "report").read_text() == "x"


def _exit_code(argv) -> int:
    """``main``'s exit status, or the parser's (it exits on a bad argument)."""
    try:
        return main(argv)
    except SystemExit as exc:
        return int(exc.code)
