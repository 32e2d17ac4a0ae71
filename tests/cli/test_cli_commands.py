"""The `volumen` command: what it prints and writes, its errors, and that it never leaks identity."""

from __future__ import annotations

import json

import numpy as np
import pytest
from PIL import Image as PILImage

import volumen
from tests.io.dicom_factory import PATIENT, write_series
from volumen.cli import main
from volumen.core import Volume


def _volume():
    rng = np.random.default_rng(0)
    data = rng.integers(-1000, 1000, size=(6, 7, 8)).astype(np.int16)
    aff = np.array([[-0.7, 0, 0, 12.5], [0, -0.9, 0, 30.0], [0, 0, 2.5, -40.0], [0, 0, 0, 1]])
    return Volume(data, spacing=(2.5, 0.9, 0.7), affine=aff, modality="CT", units="HU", name="test")


def test_info_json_reports_geometry(tmp_path, capsys):
    vol = _volume()
    volumen.save(vol, tmp_path / "v.nrrd")
    assert main(["info", str(tmp_path / "v.nrrd"), "--json"]) == 0
    facts = json.loads(capsys.readouterr().out)
    assert facts["shape_zyx"] == [6, 7, 8]
    assert facts["spacing_mm_zyx"] == [2.5, 0.9, 0.7]
    assert facts["orientation"] == "LPS"
    assert facts["value_range"] == [float(vol.data.min()), float(vol.data.max())]
    np.testing.assert_allclose(facts["affine"], vol.affine, atol=1e-6)


def test_info_text_on_dicom_never_shows_patient_identity(tmp_path, capsys):
    raw = np.arange(4 * 5 * 6, dtype=np.int16).reshape(4, 5, 6)
    pos = np.array([[0.0, 0.0, 2.5 * k] for k in range(4)])
    write_series(tmp_path / "series", raw, row_dir=(1, 0, 0), col_dir=(0, 1, 0), positions=pos,
                 patient=PATIENT, intercept=-1024)
    assert main(["info", str(tmp_path / "series")]) == 0
    out = capsys.readouterr()
    text = out.out + out.err
    assert "6 x 5 x 4 voxels" in text
    assert "HU" in text
    for value in PATIENT.values():
        for part in value.split("^"):
            assert part not in text, f"identifying value {part!r} printed"
    assert main(["info", str(tmp_path / "series"), "--json"]) == 0
    js = capsys.readouterr().out
    for value in PATIENT.values():
        assert value.split("^")[0] not in js


def test_convert_round_trip(tmp_path, capsys):
    vol = _volume()
    src = tmp_path / "v.npz"
    volumen.save(vol, src)
    assert main(["convert", str(src), str(tmp_path / "v.nii.gz")]) == 0
    back = volumen.load(tmp_path / "v.nii.gz")
    np.testing.assert_array_equal(back.data, vol.data)
    np.testing.assert_array_equal(back.affine, vol.affine)
    assert "wrote" in capsys.readouterr().out


def test_slices_writes_montage_with_radiological_orientation(tmp_path):
    # one bright voxel column on the patient's right (max x in RAS) must appear on the image's left
    data = np.zeros((5, 6, 7), np.int16)
    data[:, :, -1] = 1000
    volumen.save(Volume(data, spacing=(1, 1, 1)), tmp_path / "r.nrrd")
    assert main(["slices", str(tmp_path / "r.nrrd"), "-o", str(tmp_path / "shots"), "--window", "500,1000",
                 "--size", "0"]) == 0
    axial = np.asarray(PILImage.open(tmp_path / "shots" / "r_axial.png"))
    assert axial.shape == (6, 7)
    assert np.all(axial[:, 0] == 255) and np.all(axial[:, 1:] == 0)
    montage = np.asarray(PILImage.open(tmp_path / "shots" / "r_montage.png"))
    # rows: the tallest tile (axial, ny); columns: the axial, coronal and sagittal widths and two gaps
    assert montage.shape == (6, 7 + 4 + 7 + 4 + 6)


def test_slices_are_enlarged_to_a_readable_size_with_one_scale(tmp_path):
    """A small scan's planes are enlarged (``--size``, default ``PANEL_SIZE``) by one factor, so the largest plane's
    longest side is that many pixels and the others keep its mm per pixel; a scan that large is not shrunk."""
    from volumen.cli._slices import PANEL_SIZE

    volumen.save(Volume(np.random.default_rng(2).random((20, 30, 40)).astype(np.float32), spacing=(2, 1, 1)),
                 tmp_path / "small.nrrd")
    for size, longest in ((None, PANEL_SIZE), ("100", 100), ("30", 40)):
        shots = tmp_path / f"shots{size}"
        flags = ["--size", size] if size else []
        assert main(["slices", str(tmp_path / "small.nrrd"), "-o", str(shots), *flags]) == 0
        axial, coronal = (np.asarray(PILImage.open(shots / f"small_{p}.png")).shape for p in ("axial", "coronal"))
        assert axial == (round(30 * longest / 40), longest)  # rows A-P (30 mm), columns R-L (40 mm)
        assert coronal == (round(40 * longest / 40), longest)  # rows 20 slices of 2 mm: 40 mm, square pixels


@pytest.mark.parametrize("argv, needle", [
    (["info", "/no/such/file.nii"], "no such file"),
    (["info", "__FILE__.xyz"], "unknown volume format"),
    (["convert", "__FILE__.xyz", "out.nii"], "unknown volume format"),
    (["bench", "render", "--data", "liver", "--no-vtk"], "names no data set of aorta-244x202x224"),
])
def test_errors_are_one_line_without_traceback(tmp_path, capsys, argv, needle):
    bad = tmp_path / "thing.xyz"
    bad.write_bytes(b"not a volume")
    argv = [a.replace("__FILE__.xyz", str(bad)) for a in argv]
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert needle in err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1


def test_convert_to_unwritable_format_is_an_error(tmp_path, capsys):
    volumen.save(_volume(), tmp_path / "v.npz")
    assert main(["convert", str(tmp_path / "v.npz"), str(tmp_path / "v.vtk")]) == 1
    assert "cannot write" in capsys.readouterr().err


def test_drawing_commands_say_once_that_they_compile(monkeypatch):
    """The first compilation of one of volumen's kernels in a process writes one line (Numba's ``numba:compile``
    event: not on a cache load); other packages' compilations and later ones write nothing. Every drawing
    sub-command installs it."""
    import io

    from numba import njit
    from numba.core import event

    from volumen.cli import COMMANDS, COMPILING
    from volumen.jit import announce
    from volumen.jit._notice import MESSAGE

    assert COMPILING <= set(COMMANDS) and {"render", "fly", "mesh", "demo"} <= COMPILING

    def add_one(x):
        return x + 1

    stream = io.StringIO()
    notice = announce(stream)
    try:
        njit(lambda x: x * 2)(3)  # not volumen's: nothing
        assert stream.getvalue() == ""
        add_one.__module__ = "volumen.kernel_of_this_test"  # as a kernel of the package: once
        kernel = njit(add_one)
        kernel(1)
        kernel(2.5)
    finally:
        event.unregister("numba:compile", notice)
    assert stream.getvalue().splitlines() == [MESSAGE + " ..."]


def test_every_command_says_what_the_reader_warned_of_once(tmp_path, capsys):
    """A 4-D NIfTI holding NaN: ``slices`` (as every command that reads a volume) says on stderr that it drew the
    first volume and replaced the NaN by 0, a line each, named by the command; ``convert`` says it once;
    ``info`` lists the warnings among its facts and nowhere else."""
    import nibabel as nib

    data = np.random.default_rng(1).random((6, 7, 8, 3)).astype(np.float32)
    data[0, 0, 0, 0] = np.nan
    nib.save(nib.Nifti1Image(data, np.diag([0.8, 0.8, 1.5, 1.0])), tmp_path / "fmri.nii.gz")
    said = ("4-D image (6, 7, 8, 3): read the first volume [..., 0] only", "1 of 336 voxels are NaN or infinite")
    assert main(["slices", str(tmp_path / "fmri.nii.gz"), "-o", str(tmp_path / "shots")]) == 0
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 2 and all(line.startswith("volumen slices: warning: ") for line in err), err
    assert all(any(s in line for line in err) for s in said), err
    assert main(["convert", str(tmp_path / "fmri.nii.gz"), str(tmp_path / "first.nrrd")]) == 0
    out = capsys.readouterr()
    assert len(out.err.splitlines()) == 2 and "warning" not in out.out
    assert main(["info", str(tmp_path / "fmri.nii.gz")]) == 0
    out = capsys.readouterr()
    assert out.err == "" and sum(s in out.out for s in said) == 2


def test_many_warnings_are_counted_after_the_first_few(capsys):
    """Past ``SAID_WARNINGS`` (a folder of many skipped files) the rest are counted, not listed."""
    from volumen.cli._common import SAID_WARNINGS, say_warnings

    vol = _volume()
    vol.meta["warnings"] = [f"skipped file {k}" for k in range(SAID_WARNINGS + 3)]
    say_warnings(vol, "render")
    err = capsys.readouterr().err.splitlines()
    assert err[:SAID_WARNINGS] == [f"volumen render: warning: skipped file {k}" for k in range(SAID_WARNINGS)]
    assert err[SAID_WARNINGS:] == ["volumen render: warning: 3 more (volumen info lists them)"]


def test_cpr_window_is_level_and_width_as_in_slices(tmp_path):
    """``cpr --window 40,400`` is level 40, width 400 (values -160..240), as ``slices --window``; a name is a CT
    window."""
    from volumen.cli._cpr import load_centerline
    from volumen.endoscopy import cpr_figure, curved_reformation

    rng = np.random.default_rng(3)
    volumen.save(Volume(rng.integers(-1000, 1000, size=(8, 9, 10)).astype(np.int16), spacing=(2.0, 1.0, 1.0),
                        modality="CT", units="HU"), tmp_path / "ct.nrrd")
    pts = [[4.0, 4.0, 2.0 * z] for z in range(8)]
    arc = [2.0 * z for z in range(8)]
    (tmp_path / "path.json").write_text(json.dumps({"points": pts, "radius": [2.0] * 8, "arc": arc}))
    vol, cl = volumen.load(tmp_path / "ct.nrrd"), load_centerline(tmp_path / "path.json")
    cpr = curved_reformation(vol, cl, kind="straightened", width=40.0)
    for window, lo_hi in (("40,400", (-160.0, 240.0)), ("bone", (-500.0, 1300.0))):
        out = tmp_path / f"cpr-{window}.png"
        assert main(["cpr", str(tmp_path / "ct.nrrd"), "--path", str(tmp_path / "path.json"), "-o", str(out),
                     "--window", window, "--sections", "4", "--height", "100", "--width", "40"]) == 0
        expected = cpr_figure(vol, cl, cpr, [4.0], window=lo_hi, section_width=40.0, height=100)
        np.testing.assert_array_equal(np.asarray(PILImage.open(out)), expected)
