"""The lumen estimate in the application: the endoscopy panel finds the lumen with the same estimate as
``volumen fly`` (on the washout phantom, whose contrast fades along the artery), draws the lumen's own wall while
flying, and refuses a leak with the same one-line message as the command line."""

from __future__ import annotations

import numpy as np
import pytest


def _compute(panel, qtbot, start, end):
    panel.pick("endo-start", np.asarray(start, float))
    panel.pick("endo-end", np.asarray(end, float))
    task = panel.compute()
    qtbot.waitUntil(lambda: task.finished, timeout=120000)


def test_panel_uses_the_command_lines_estimate_and_draws_the_lumens_wall(make_window, qtbot):
    from volumen.data import phantom
    from volumen.endoscopy import lumen_wall

    vol = phantom("washout")
    marks, truth = vol.meta["truth"]["landmarks"], vol.meta["truth"]["artery"].mask
    win = make_window(load=False)
    win.set_volume(vol, "phantom:washout")
    panel = win.endo_panel
    _compute(panel, qtbot, marks["start"], marks["end"])
    m = panel.model
    cli = lumen_wall(vol, marks["start"], marks["end"])
    from volumen.core import values_of

    said = m.estimate.describe(**values_of(vol))  # the command line's line, in the scan's units' precision
    print(said)
    assert m.estimate == cli.estimate and np.array_equal(m.mask, cli.mask)
    assert said in panel.status.text()
    overlay = np.asarray(win.state.mask.data, bool)
    assert 2 * np.sum(overlay & truth) / (overlay.sum() + truth.sum()) >= 0.9  # the lumen shown, Dice
    panel.play()
    drawn = win.state.scene.volume
    assert drawn is m.drawn_volume() and drawn.shape != vol.shape  # the lumen's wall, on the lumen's box
    bone = vol.data > 1000  # the femur's cortex, beside the artery: held to the wall's value in the box
    world = vol.index_to_world(np.argwhere(bone)[:, ::-1].astype(float))
    ijk = np.rint(drawn.world_to_index(world)).astype(int)
    inside = np.all((ijk >= 0) & (ijk < np.array(drawn.shape[::-1])), axis=1)
    assert inside.any() and np.all(drawn.data[tuple(ijk[inside][:, ::-1].T)] <= m.estimate.threshold)
    panel.stop()
    assert win.state.scene.volume is vol


def test_panel_refuses_a_leak_as_the_command_line_does(make_window, qtbot, monkeypatch):
    from volumen.data import phantom
    from volumen.endoscopy import lumen_wall
    from volumen.errors import LumenError

    vol = phantom("airways", fistula=2.0)
    marks = vol.meta["truth"]["landmarks"]
    pocket, neck = np.array(marks["pocket"]), np.array(marks["neck"])
    start = neck + 4.0 * (pocket - neck) / np.linalg.norm(pocket - neck)
    with pytest.raises(LumenError) as refused:
        lumen_wall(vol, start, marks["end"])
    win = make_window(load=False)
    win.set_volume(vol, "phantom:airways?fistula=2")
    errors = []
    monkeypatch.setattr(win, "report_error", lambda title, text: errors.append((title, text)))
    _compute(win.endo_panel, qtbot, start, marks["end"])
    print(errors)
    assert errors == [("No centerline", str(refused.value))] and "the lumen leaks" in errors[0][1]
    assert win.endo_panel.model.centerline is None
