"""Numbers a command takes are finite (and sizes not negative): ``nan`` or ``inf`` in a window, a shift or a point
is one line and exit 1, nothing written, instead of a black picture with exit 0."""

from __future__ import annotations

import pytest

from volumen.cli import main


@pytest.mark.parametrize("argv", [["slices", "phantom:head?size=16", "-o", "{out}", "--window", "nan,100"],
                                  ["slices", "phantom:head?size=16", "-o", "{out}", "--window", "40,inf"],
                                  ["render", "phantom:head?size=16", "-o", "{out}/x.png", "--shift", "nan"],
                                  ["render", "phantom:head?size=16", "-o", "{out}/x.png", "--iso", "inf"],
                                  ["slices", "phantom:head?size=16", "-o", "{out}", "--at", "0,nan,0"],
                                  ["slices", "phantom:head?size=16", "-o", "{out}", "--size", "-5"]])
def test_a_number_that_is_not_finite_is_refused_in_one_line(argv, tmp_path, capsys):
    out = tmp_path / "out"
    try:
        code = main([a.format(out=out) for a in argv])
    except SystemExit as exc:  # the parser's refusals exit
        code = exc.code
    assert code == 1
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "error" in err
    assert not out.exists()


def test_a_shift_a_mode_does_not_use_is_said(tmp_path, capsys):
    assert main(["render", "phantom:head?size=16", "-o", str(tmp_path / "m.png"), "--mode", "mip", "--shift", "100",
                 "--size", "16x16"]) == 0
    assert "--shift moves the transfer function, which --mode mip does not use" in capsys.readouterr().err
