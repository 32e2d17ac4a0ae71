"""``volumen cpr``: the CPR of a saved flight as a PNG, its cross-sections marked in colour."""

from __future__ import annotations

import numpy as np
from PIL import Image

from volumen.cli import main
from volumen.endoscopy import Flight
from volumen.endoscopy.views._cpr_figure import MARK_COLORS


def test_cpr_of_a_saved_flight(tmp_path, capsys, torso):
    flight = tmp_path / "colon.json"
    assert main(["fly", "phantom:torso", "--auto", "-o", str(tmp_path / "c.gif"), "--size", "16x16", "--frames", "2",
                 "--no-progress", "--save-path", str(flight)]) == 0
    cl = Flight.load(flight, torso).centerline
    for kind in ("straightened", "stretched"):
        out = tmp_path / f"{kind}.png"
        assert main(["cpr", "phantom:torso", "--path", str(flight), "-o", str(out), "--kind", kind,
                     "--sections", "50,200,400", "--height", "300"]) == 0
        img = np.asarray(Image.open(out))
        for color in MARK_COLORS[:3]:  # each section's colour is on the picture (ticks and frame)
            assert np.all(img == color, axis=2).sum() > 20
        assert abs(img.shape[0] - 300) <= 150
    printed = capsys.readouterr().out
    assert f"along {cl.length:.1f} mm" in printed and "cross-sections at 50.0, 200.0, 400.0 mm" in printed
    assert main(["cpr", "phantom:torso", "--path", str(flight), "-o", str(tmp_path / "x.png"),
                 "--sections", "9999"]) == 1
    assert "outside the path" in capsys.readouterr().err
    (tmp_path / "bad.json").write_text("{}")
    assert main(["cpr", "phantom:torso", "--path", str(tmp_path / "bad.json"), "-o", str(tmp_path / "y.png")]) == 1
    assert "not a flight, centerline or keyframe path" in capsys.readouterr().err
    assert not (tmp_path / "x.png").exists() and not (tmp_path / "y.png").exists()
