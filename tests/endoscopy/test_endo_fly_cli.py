"""``volumen fly``: a tiny MP4 (and GIF) of the phantom, decoded back; the timing log beside it."""

import argparse
import json

import numpy as np
import pytest

from volumen.cli import _fly


def _run(argv):
    p = argparse.ArgumentParser()
    sub = p.add_subparsers(dest="command")
    _fly.register(sub)
    args = p.parse_args(["fly", *argv])
    return _fly.run(args)


def test_fly_auto_writes_a_playable_mp4(tmp_path, capsys):
    import imageio.v2 as iio

    out = tmp_path / "fly.mp4"
    assert _run(["phantom:torso", "--auto", "-o", str(out), "--size", "48x48", "--frames", "10", "--no-progress",
                 "--save-path", str(tmp_path / "path.json")]) == 0
    reader = iio.get_reader(str(out))
    frames = [f for f in reader]
    reader.close()
    assert len(frames) == 10 and frames[0].shape == (48, 48, 3)
    assert np.mean(frames[3]) > 20  # not black
    timing = json.loads((tmp_path / "fly.timing.json").read_text())
    t = np.array(timing["times_s"])
    assert timing["frames"] == 10 and timing["weighted_mean_s"] == pytest.approx((t * t).sum() / t.sum())
    printed = capsys.readouterr().out
    assert "weighted mean" in printed and "centerline" in printed
    # the saved path plays again, both ways, into a GIF
    gif = tmp_path / "again.gif"
    assert _run(["phantom:torso", "--path", str(tmp_path / "path.json"), "-o", str(gif), "--size", "32x24",
                 "--frames", "3", "--both-directions", "--no-progress"]) == 0
    g = iio.mimread(str(gif))
    # out and back, 3 + 3 frames: the return leg is turned round (it looks where the camera goes), so at the
    # turn the same position shows the other way
    assert len(g) == 6 and g[0].shape[:2] == (24, 32)
    assert not np.array_equal(g[2], g[3]) and not np.array_equal(g[0], g[5])


def test_fly_rejects_bad_options(tmp_path):
    with pytest.raises(ValueError, match="mp4"):
        _run(["phantom:torso", "--auto", "-o", str(tmp_path / "x.avi")])
    with pytest.raises(ValueError, match="--end"):
        _run(["phantom:torso", "--start", "0,0,0", "-o", str(tmp_path / "x.mp4")])
