"""``volumen fly`` from real-world input: negative coordinates, an existing segmentation as the lumen, flights
saved and replayed bit for bit, and one-line errors that leave nothing written."""

from __future__ import annotations

import argparse
import json

import numpy as np
import pytest

from volumen.cli import _fly, main
from volumen.cli._common import join_negative_values
from volumen.endoscopy import Flight, find_lumen, lumen_wall

TINY = ["--size", "24x24", "--frames", "3", "--no-progress"]


def _args(argv):
    p = argparse.ArgumentParser()
    _fly.register(p.add_subparsers(dest="command"))
    return p.parse_args(["fly", *join_negative_values(argv)])


def test_negative_coordinates_are_values_not_options():
    args = _args(["phantom:torso", "--start", "-10.5,40,120", "--end", "-60,-30,-80", "-o", "x.mp4"])
    assert args.start == "-10.5,40,120" and args.end == "-60,-30,-80"
    assert join_negative_values(["--end", "-1e2", "-o", "a"]) == ["--end=-1e2", "-o", "a"]


def _nifti(path, data, affine):
    import nibabel as nib

    nib.save(nib.Nifti1Image(np.asarray(data), np.asarray(affine, float)), str(path))


def test_lumen_mask_reproduces_the_grown_flight(tmp_path, torso):
    """The grown lumen written as label 3 of a label map (NIfTI, by nibabel), as a TotalSegmentator folder, and on
    a flipped and cropped grid, gives the same keyframes, centerline and lumen as growing; the wall threshold read
    from the mask's boundary values is within 2 % of the lumen-wall contrast of the one estimated round the start
    (the same edge, read two ways), and the three mask flights are identical."""
    colon = torso.meta["truth"]["colon"]
    start, end = colon.centerline[0], colon.centerline[-1]
    lumen = lumen_wall(torso, start, end).mask  # grown as volumen fly grows it: from both points
    labels = np.where(lumen, 3, 0).astype(np.int16)
    labels[:5][~lumen[:5]] = 7  # another structure, around the lumen
    _nifti(tmp_path / "labels.nii.gz", labels.transpose(2, 1, 0), torso.affine)  # nibabel is (i, j, k)
    (tmp_path / "seg").mkdir()
    _nifti(tmp_path / "seg" / "colon.nii.gz", lumen.astype(np.uint8).transpose(2, 1, 0), torso.affine)
    flip = torso.affine @ np.array([[-1, 0, 0, torso.shape[2] - 1], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])
    _nifti(tmp_path / "flipped.nii.gz", lumen[:, :, ::-1].astype(np.uint8).transpose(2, 1, 0), flip)
    pts = ",".join(f"{v:.3f}" for v in start), ",".join(f"{v:.3f}" for v in end)
    flights = {}
    for name, extra in [("grown", []), ("label", ["--lumen-mask", str(tmp_path / "labels.nii.gz"), "--label", "3"]),
                        ("folder", ["--lumen-mask", str(tmp_path / "seg"), "--label", "colon"]),
                        ("flipped", ["--lumen-mask", str(tmp_path / "flipped.nii.gz")])]:
        save = tmp_path / f"{name}.json"
        assert main(["fly", "phantom:torso", "--start", pts[0], "--end", pts[1], "-o", str(tmp_path / f"{name}.gif"),
                     "--save-path", str(save), *TINY, *extra]) == 0
        flights[name] = json.loads(save.read_text())
    grown = flights["grown"]
    for name in ("label", "folder", "flipped"):
        f = flights[name]
        assert f == flights["label"], name
        assert f["path"] == grown["path"] and f["centerline"] == grown["centerline"], name
        assert f["lumen"]["bits"] == grown["lumen"]["bits"] and f["lumen"]["box"] == grown["lumen"]["box"], name
        spread = grown["lumen"]["estimate"]["spread"]
        print(name, f["endoscope"]["threshold"], grown["endoscope"]["threshold"], spread)
        assert abs(f["endoscope"]["threshold"] - grown["endoscope"]["threshold"]) <= 0.02 * spread, name


def test_saved_flight_reproduces_every_frame_bit_for_bit(tmp_path, torso):
    for mode in ("isosurface", "composite"):
        args = _args(["phantom:torso", "--auto", "-o", str(tmp_path / "x.mp4"), "--mode", mode, *TINY])
        flight, _ = _fly._flight(args, torso)
        flight.save(tmp_path / f"{mode}.json")
        again = Flight.load(tmp_path / f"{mode}.json", torso)
        assert again.endoscope.to_dict() == flight.endoscope.to_dict()
        for pose_a, pose_b in zip(flight.path.play(10, 4), again.path.play(10, 4), strict=True):
            a, b = flight.endoscope.render(pose_a, (24, 24)), again.endoscope.render(pose_b, (24, 24))
            assert np.array_equal(a.rgba, b.rgba) and np.array_equal(a.depth, b.depth), mode
            assert a.alpha.mean() > 0.5
    # a replayed flight keeps its settings; flags given override them
    replay, _ = _fly._flight(_args(["phantom:torso", "--path", str(tmp_path / "isosurface.json"), "-o", "y.mp4"]),
                             torso)
    assert replay.endoscope.to_dict() == Flight.load(tmp_path / "isosurface.json", torso).endoscope.to_dict()
    changed, _ = _fly._flight(_args(["phantom:torso", "--path", str(tmp_path / "isosurface.json"), "-o", "y.mp4",
                                     "--mode", "composite", "--fov", "80"]), torso)
    assert changed.endoscope.mode == "composite" and changed.endoscope.jitter and changed.endoscope.fov == 80


def _fails(argv, tmp_path, capsys, match):
    code = main(argv)
    err = capsys.readouterr().err.strip()
    print(err)
    assert code == 1 and len(err.splitlines()) == 1 and err.startswith("volumen fly: error:")
    assert match in err, err
    assert sorted(p.name for p in tmp_path.iterdir() if p.suffix in (".gif", ".mp4", ".json")) == []
    return err


def _p(v):
    return ",".join(f"{x:.2f}" for x in v)


def test_bad_points_and_masks_get_one_line_and_write_nothing(tmp_path, capsys, torso):
    colon, airway = torso.meta["truth"]["colon"], torso.meta["truth"]["airway"]
    out = ["-o", str(tmp_path / "f.gif"), "--save-path", str(tmp_path / "f.json"), *TINY]
    _fails(["fly", "phantom:torso", "--start", "-900,0,0", "--end", _p(colon.centerline[-1]), *out], tmp_path,
           capsys, "the start point (-900.0, 0.0, 0.0) mm lies outside the scan")
    _fails(["fly", "phantom:torso", "--start", _p(colon.centerline[0]), "--end", "0,0,5000", *out], tmp_path,
           capsys, "the end point (0.0, 0.0, 5000.0) mm lies outside the scan")
    _fails(["fly", "phantom:torso", "--start", _p(colon.centerline[0]), "--end", _p(airway.centerline[0]), *out],
           tmp_path, capsys, "lies in a lumen that does not connect to the start point's")
    two = (torso.meta["truth"]["colon"].mask | torso.meta["truth"]["airway"].mask).astype(np.uint8)
    _nifti(tmp_path / "two.nii.gz", two.transpose(2, 1, 0), torso.affine)
    _fails(["fly", "phantom:torso", "--start", _p(colon.centerline[0]), "--end", _p(airway.centerline[0]),
            "--lumen-mask", str(tmp_path / "two.nii.gz"), *out], tmp_path, capsys,
           "two.nii.gz: the end point (4.0, 0.0, 198.0) mm lies in a part of the mask that does not connect to the "
           "start")
    _fails(["fly", "phantom:torso", "--start", "0,-80,0", "--end", _p(airway.centerline[0]),
            "--lumen-mask", str(tmp_path / "two.nii.gz"), *out], tmp_path, capsys,
           "two.nii.gz: the start point (0.0, -80.0, 0.0) mm is not in the lumen mask")
    shifted = torso.affine.copy()
    shifted[:3, 3] += 5000.0
    _nifti(tmp_path / "elsewhere.nii.gz", np.ones(torso.shape[::-1], np.uint8), shifted)
    _fails(["fly", "phantom:torso", "--auto", "--lumen-mask", str(tmp_path / "elsewhere.nii.gz"), *out], tmp_path,
           capsys, "elsewhere.nii.gz: the mask does not overlap the scan")


def test_two_unconnected_lumens_name_the_end_point(torso):
    from volumen.errors import LumenError

    colon, airway = torso.meta["truth"]["colon"], torso.meta["truth"]["airway"]
    with pytest.raises(LumenError, match="the end point .* lies in a lumen that does not connect to the start"):
        find_lumen(torso, colon.centerline[0], airway.centerline[0])


def test_a_leak_is_refused_in_one_line_and_nothing_written(tmp_path, capsys, unseen):
    """A start in an air pocket that touches the trachea through a 2 mm neck (about one voxel of air once
    blurred): growing from it breaks into the airways before the end; one line naming the leak and the flags to
    try, exit 1, neither video nor flight written."""
    marks = unseen("airways", fistula=2.0).meta["truth"]["landmarks"]
    pocket, neck = np.array(marks["pocket"]), np.array(marks["neck"])
    start = neck + 4.0 * (pocket - neck) / np.linalg.norm(pocket - neck)
    out = ["-o", str(tmp_path / "f.mp4"), "--save-path", str(tmp_path / "f.json"), *TINY]
    line = _fails(["fly", "phantom:airways?fistula=2", "--start", _p(start), "--end", _p(marks["end"]), *out],
                  tmp_path, capsys, "the lumen leaks: growing from the start point")
    assert all(flag in line for flag in ("--range LO,HI", "--threshold T", "--lumen-mask FILE")), line
