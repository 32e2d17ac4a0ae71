"""The error contract of every command: a wrong choice, a missing file, a point outside the volume or a missing
optional package is one line on stderr naming the command, exit status 1, and nothing written."""

from __future__ import annotations

import json
import sys

import numpy as np
import pytest

import volumen
from volumen.cli import main
from volumen.core import Volume, slice_image
from volumen.errors import MissingExtraError, ModalityError, OutsideVolumeError, UnknownChoiceError


@pytest.fixture
def work(tmp_path, monkeypatch):
    """A folder holding a small CT (``ct.nrrd``), an MRI (``mr.nrrd``), a centerline through the CT
    (``path.json``) and a manifest of one study (``manifest.csv``); the commands run in it."""
    rng = np.random.default_rng(0)
    ct = rng.integers(-1000, 1000, size=(8, 9, 10)).astype(np.int16)
    ct[0, 0, 0] = 1500
    volumen.save(Volume(ct, spacing=(2.0, 1.0, 1.0), modality="CT", units="HU"), tmp_path / "ct.nrrd")
    mr = (rng.random((8, 9, 10)) * 900).astype(np.float32)
    volumen.save(Volume(mr, spacing=(2.0, 1.0, 1.0), modality="MR"), tmp_path / "mr.nrrd")
    pts = np.array([[4.0, 4.0, 2.0 * z] for z in range(8)])
    (tmp_path / "path.json").write_text(json.dumps({"points": pts.tolist(), "radius": [2.0] * 8,
                                                    "arc": (2.0 * np.arange(8)).tolist()}))
    (tmp_path / "manifest.csv").write_text("id,path,settings,outputs\nct,ct.nrrd,{},png\n")
    monkeypatch.chdir(tmp_path)
    return tmp_path


def _files(folder):
    return sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*"))


def _fails_in_one_line(argv, work, capsys, *needles):
    """Run ``volumen ARGV``: exit 1, one line on stderr naming the command and holding ``needles``, nothing
    written."""
    before = _files(work)
    try:
        code = main(argv)
    except SystemExit as exc:  # the parser's refusals exit
        code = exc.code
    err = capsys.readouterr().err
    assert code == 1, err
    lines = err.strip().splitlines()
    named = (f"volumen {argv[0]}", f"volumen {' '.join(argv[:2])}")  # a pacs action's own parser names the action
    assert len(lines) == 1 and ": error: " in lines[0] and lines[0].split(": error: ")[0] in named, err
    assert "Traceback" not in err and "internal error" not in err
    for needle in needles:
        assert needle in err, err
    assert _files(work) == before, "a failed command left output behind"
    return lines[0]


@pytest.mark.parametrize("argv, needles", [
    (["render", "ct.nrrd", "-o", "out/x.png", "--preset", "ct-vessel"],
     ["--preset 'ct-vessel' is not one of ct-bone", "did you mean 'ct-vessels'?"]),
    (["render", "ct.nrrd", "-o", "x.png", "--view", "front"], ["--view 'front'", "anterior, posterior"]),
    (["render", "ct.nrrd", "-o", "x.png", "--mode", "mpi"], ["did you mean 'mip'?"]),
    (["info", "ct.nrrd", "--nonfinite", "zeros"], ["did you mean 'zero'?"]),
    (["convert", "ct.nrrd", "c.nii", "--zarr-format", "4"], ["--zarr-format 4 is not one of 2, 3"]),
    (["slices", "ct.nrrd", "-o", "shots", "--window", "brian"], ["window 'brian'", "did you mean 'brain'?"]),
    (["slices", "ct.nrrd", "-o", "shots", "--window", "soft"], ["did you mean 'soft-tissue'?"]),  # cut short
    (["slices", "ct.nrrd", "-o", "shots", "--window", "40"], ["LEVEL,WIDTH"]),
    (["cpr", "ct.nrrd", "--path", "path.json", "-o", "c.png", "--kind", "straighten"],
     ["did you mean 'straightened'?"]),
    (["cpr", "ct.nrrd", "--path", "path.json", "-o", "c.png", "--window", "bones"], ["did you mean 'bone'?"]),
    (["fly", "ct.nrrd", "-o", "f.gif", "--mode", "composit"], ["did you mean 'composite'?"]),
    (["mesh", "ct.nrrd", "-o", "m.stl", "--nonfinite", "nan"], ["--nonfinite 'nan'"]),
    (["serve", "ct.nrrd", "--preset", "ct-vessel", "--no-browser"], ["did you mean 'ct-vessels'?"]),
    (["bench", "rendr"], ["did you mean 'render'?"]),
])
def test_a_wrong_choice_names_it_the_valid_ones_and_the_closest(work, capsys, argv, needles):
    _fails_in_one_line(argv, work, capsys, *needles)


def test_a_wrong_command_names_the_closest(work, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["rendr", "ct.nrrd"])
    err = capsys.readouterr().err
    assert exc.value.code == 1 and len(err.strip().splitlines()) == 1, err
    assert err.startswith("volumen: error: ") and "command 'rendr'" in err and "did you mean 'render'?" in err


@pytest.mark.parametrize("argv", [
    ["info", "no-such.nii"],
    ["convert", "no-such.nii", "c.nrrd"],
    ["slices", "no-such.nii", "-o", "shots"],
    ["render", "no-such.nii", "-o", "x.png"],
    ["fly", "no-such.nii", "-o", "f.gif", "--auto"],
    ["cpr", "no-such.nii", "--path", "path.json", "-o", "c.png"],
    ["mesh", "no-such.nii", "-o", "m.stl"],
    ["serve", "no-such.nii", "--no-browser"],
])
def test_a_missing_file_is_one_line_naming_it(work, capsys, argv):
    _fails_in_one_line(argv, work, capsys, "no-such.nii", "no such file")


def test_a_missing_manifest_or_path_file_is_one_line(work, capsys):
    _fails_in_one_line(["cpr", "ct.nrrd", "--path", "nowhere.json", "-o", "c.png"], work, capsys, "nowhere.json")
    _fails_in_one_line(["batch", "nowhere.csv", "--out", "results", "--no-progress"], work, capsys, "nowhere.csv")


@pytest.mark.parametrize("argv, needles", [
    (["slices", "ct.nrrd", "-o", "shots", "--at", "0,0,900"],
     ["point (0, 0, 900) mm", "ct.nrrd", "x 0.0..9.0, y 0.0..8.0, z 0.0..14.0 mm"]),
    (["slices", "ct.nrrd", "-o", "shots/deeper", "--at", "-50,4,4"], ["point (-50, 4, 4) mm", "ct.nrrd"]),
    (["fly", "ct.nrrd", "-o", "f.gif", "--start", "0,0,900", "--end", "4,4,4"],
     ["(0.0, 0.0, 900.0) mm lies outside the scan"]),
    (["cpr", "ct.nrrd", "--path", "path.json", "-o", "c.png", "--sections", "99"], ["outside the path (0..14.0 mm)"]),
])
def test_a_point_outside_is_said_in_millimetres_with_the_extent(work, capsys, argv, needles):
    _fails_in_one_line(argv, work, capsys, *needles)


@pytest.mark.parametrize("argv, needles", [
    (["pacs", "fnd", "archive"], ["command 'fnd' is not one of echo, find, get, send", "did you mean 'find'?"]),
    (["pacs", "find", "archive", "--protocol", "dicomwb"], ["--protocol 'dicomwb'", "did you mean 'dicomweb'?"]),
    (["pacs", "echo", "nosuch"], ["server nosuch: is not a configured server", "servers.toml"]),
    (["pacs", "get", "nosuch", "1.2.3", "-o", "fetched"], ["server nosuch: is not a configured server"]),
    (["pacs", "send", "http://127.0.0.1:9/dicom-web", "no-such.dcm"], ["no-such.dcm", "No such file"]),
    (["pacs", "send", "http://127.0.0.1:9/dicom-web", "--scan", "no-such", "--picture", "x.png", "--save", "c.dcm"],
     ["no-such: no such file"]),
    (["pacs", "send", "http://127.0.0.1:9/dicom-web", "--picture", "x.png"], ["--picture need --scan"]),
])
def test_pacs_refuses_in_one_line_before_it_writes_or_connects(work, capsys, monkeypatch, argv, needles):
    """A wrong action or protocol, a server name servers.toml does not hold (an empty configuration folder), a
    missing file: one line, exit 1, no fetched/ or SEG written (the address on port 9 is never reached)."""
    monkeypatch.setenv("VOLUMEN_CONFIG_DIR", str(work / "config"))
    _fails_in_one_line(argv, work, capsys, *needles)


def test_serve_takes_the_browser_window_as_size_as_window_is_level_width_elsewhere():
    from volumen.cli import build_parser

    args = build_parser().parse_args(["serve", "ct.nrrd", "--screenshot", "s.png", "--size", "320x200"])
    assert args.size == "320x200" and not hasattr(args, "window")


def test_slice_image_outside_raises_the_typed_error():
    vol = Volume(np.zeros((4, 5, 6), np.int16), spacing=(2.0, 1.0, 1.0), modality="CT", units="HU", name="tiny")
    with pytest.raises(OutsideVolumeError, match=r"point \(0, 0, 40\) mm .* tiny, which spans .* z 0.0..6.0 mm"):
        slice_image(vol, "axial", world=(0, 0, 40))
    with pytest.raises(IndexError):  # still an IndexError for callers that caught one
        slice_image(vol, "coronal", index=9)
    with pytest.raises(UnknownChoiceError, match="did you mean 'axial'"):
        slice_image(vol, "axail")


def _missing(monkeypatch, *modules):
    """Make ``import MODULE`` fail as it does where the package is not installed."""
    for m in modules:
        monkeypatch.setitem(sys.modules, m, None)


@pytest.mark.parametrize("argv, modules, extra", [
    (["view", "ct.nrrd", "--screenshot", "shot.png"], ["PySide6"], "gui"),
    (["batch", "manifest.csv", "--out", "results", "--no-progress"], ["distributed"], "scale"),
    (["fly", "ct.nrrd", "-o", "f.mp4", "--auto"], ["imageio_ffmpeg"], "video"),
    (["convert", "ct.nrrd", "ct.ome.zarr"], ["zarr"], "scale"),
])
def test_a_missing_extra_names_it(work, capsys, monkeypatch, argv, modules, extra):
    _missing(monkeypatch, *modules)
    _fails_in_one_line(argv, work, capsys, f"pip install 'volumen[{extra}]'")


def test_opengl_without_moderngl_names_the_extra(work, capsys, monkeypatch):
    from volumen.render.raster import _context

    _missing(monkeypatch, "moderngl")
    monkeypatch.setattr(_context, "_state", {})  # no context made or refused yet in this process
    _fails_in_one_line(["render", "ct.nrrd", "-o", "x.png", "--device", "gl"], work, capsys,
                       "pip install 'volumen[gl]'")


def test_the_notebook_viewer_without_ipywidgets_names_the_extra(monkeypatch):
    _missing(monkeypatch, "ipywidgets")
    vol = Volume(np.zeros((4, 5, 6), np.int16), spacing=(1.0, 1.0, 1.0))
    with pytest.raises(MissingExtraError, match=r"volumen.show needs ipywidgets: pip install 'volumen\[notebook\]'"):
        volumen.show(vol)


def test_a_ct_window_on_an_mri_is_refused_in_one_line(work, capsys):
    line = _fails_in_one_line(["slices", "mr.nrrd", "-o", "shots", "--window", "brain"], work, capsys,
                              "'brain' is a CT window in HU", "not a CT (modality MR", "LEVEL,WIDTH")
    assert "display range is level" in line
    vol = volumen.load(work / "mr.nrrd")
    with pytest.raises(ModalityError):
        slice_image(vol, "axial", window="bone")


def test_an_unexpected_failure_is_still_one_line_with_status_3(work, capsys, monkeypatch):
    import volumen.cli._info as info

    monkeypatch.setattr(info, "run", lambda args: 1 / 0)
    assert main(["info", "ct.nrrd"]) == 3
    err = capsys.readouterr().err
    assert err.startswith("volumen info: internal error: ZeroDivisionError") and len(err.splitlines()) == 1
