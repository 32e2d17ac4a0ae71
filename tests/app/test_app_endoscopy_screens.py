"""Endoscopy in the window, the main-window screenshot for the README, and ``volumen view --screenshot``."""

from __future__ import annotations

import argparse

import numpy as np
import pytest
from PySide6.QtCore import QPoint, Qt

VIEW = 160


def test_blocked_endoscopy_move_keeps_the_camera_in_the_lumen(make_window, qtbot, head64):
    pytest.importorskip("skimage", reason="the centerline needs scikit-image (volumen.endoscopy)")
    win = make_window()
    tube = head64.meta["truth"]["nasal_airway"].centerline
    panel = win.endo_panel
    # pick the start and the end by clicking in the sagittal view (the airway runs in the mid-sagittal plane)
    sag = win.slices["sagittal"]
    for mode, point in (("endo-start", tube[len(tube) // 4]), ("endo-end", tube[-1])):
        win.state.set_crosshair(point)
        win.set_pick_mode(mode)
        x, y = sag.world_to_widget(point)
        qtbot.mouseClick(sag, Qt.LeftButton, pos=QPoint(int(round(x)), int(round(y))))
    assert panel.model.start is not None and panel.model.end is not None
    task = panel.compute()
    qtbot.waitUntil(lambda: task.finished, timeout=60000)
    cl = panel.model.centerline
    assert cl is not None and cl.length > 40
    assert win.view3d.centerline is cl and sag.endoscopy.centerline is cl
    panel.start_manual()
    assert win.view3d.flying
    for _ in range(18):  # turn to face the wall
        qtbot.keyClick(win.view3d, Qt.Key_Left)
    blocked = False
    for _ in range(40):
        qtbot.keyClick(win.view3d, Qt.Key_W)
        if panel.model.blocked:
            blocked = True
            break
    assert blocked and win.view3d.blocked_marker
    eye = np.asarray(win.state.camera.position)
    i, j, k = np.rint(head64.world_to_index(eye)).astype(int)
    assert head64.data[k, j, i] < -400  # still in the air of the lumen
    assert panel.model.collider.clearance(eye) >= panel.model.margin - 0.05
    assert win.wait_for_final(60)
    panel.stop()
    assert not win.view3d.flying and win.state.scene.transfer.name != "endo-air"


def test_main_window_screenshot_with_lights(make_window, qtbot, app_output, head64):
    from volumen.app._light_panel import add_light_at_camera
    from volumen.app._overlays import light_cone
    from volumen.app._screenshot import save_widget
    from volumen.core.gestures import orbit, zoom

    win = make_window(size=(1200, 800), fixed=False)
    st = win.state
    cam0 = st.camera
    for az, el in ((-40, 20), (45, -10)):  # two lights placed near the head, shining at it
        st.set_camera(zoom(orbit(cam0, az / 0.5, el / 0.5), 3.2))
        add_light_at_camera(st)
    st.set_camera(cam0)
    st.set_camera(zoom(orbit(cam0, -30, 10), 0.8))
    st.select_light(1)
    win.tf_editor.apply_preset("ct-skin-bone")
    assert win.wait_for_final(60)
    size = win.view3d.view_size
    for light in st.scene.lights:
        cone = light_cone(light, st.camera, size, win.view3d.light_length())
        assert cone.visible and np.all((cone.apex > 0) & (cone.apex < size))
    path = save_widget(win, app_output / "main_window.png")
    assert path.stat().st_size > 10000
    # the cones are drawn over the picture: the view's grab differs from the rendered frame at the apexes
    grab = win.view3d.grab().toImage()
    for light in st.scene.lights:
        x, y = light_cone(light, st.camera, size, win.view3d.light_length()).apex
        c = grab.pixelColor(int(x), int(y))
        assert (c.red(), c.green(), c.blue()) != tuple(win.view3d.frame.rgb[int(y), int(x)])


def test_view_command_writes_a_screenshot_of_a_session(make_window, tmp_path):
    from volumen.cli import _view

    win = make_window()
    win.tf_editor.apply_preset("ct-bone")
    session = tmp_path / "s.json"
    win.save_session(session)
    win.close()
    parser = argparse.ArgumentParser()
    _view.register(parser.add_subparsers())
    out = tmp_path / "shot.png"
    args = parser.parse_args(["view", "--session", str(session), "--screenshot", str(out), "--size", "700x480"])
    assert _view.run(args) == 0
    from PIL import Image

    img = np.asarray(Image.open(out))
    assert img.shape[1] == 700 and 480 <= img.shape[0] <= 600 and img.std() > 10  # height: at least the panels
    with pytest.raises(ValueError, match="--size"):
        _view.run(parser.parse_args(["view", "--size", "10x10"]))
