"""The main window on the head phantom: linked views, mouse and keys, presets, sessions, errors, responsiveness."""

from __future__ import annotations

import time

import numpy as np
import pytest
from PySide6.QtCore import QPoint, QPointF, Qt
from PySide6.QtGui import QWheelEvent
from PySide6.QtWidgets import QApplication, QMessageBox

from volumen.render import TECHNIQUES

VIEW = 160  # the 3D view side set by the make_window fixture


def _rgb(win) -> np.ndarray:
    return win.view3d.frame.rgb.astype(int)


def _angle(a, b) -> float:
    a, b = np.asarray(a, float), np.asarray(b, float)
    return float(np.degrees(np.arccos(np.clip(a @ b / np.linalg.norm(a) / np.linalg.norm(b), -1, 1))))


def test_four_views_show_the_phantom_and_the_3d_picture_is_upright(make_window, head64):
    win = make_window()
    assert win.view3d.frame.final and win.view3d.frame.rgb.shape == (VIEW, VIEW, 3)
    rgb = _rgb(win)
    assert rgb.sum(axis=2).astype(bool).mean() > 0.15  # the head fills part of the view
    # upright: the skull's top is in the upper part of the picture, the neck narrower than the cranium
    rows = np.nonzero(rgb.sum(axis=(1, 2)))[0]
    widths = (rgb.sum(axis=2) > 0).sum(axis=1)
    top, bottom = rows[0], rows[-1]
    assert widths[top + (bottom - top) // 4] > widths[bottom - (bottom - top) // 8]
    for view in win.slices.values():
        assert view.geometry_ is not None and view.index == view.geometry_.index_of(head64.center)


def test_mouse_drag_orbits_the_camera_by_the_expected_angle(make_window, qtbot):
    from volumen.core.gestures import DEGREES_PER_PIXEL

    win = make_window()
    cam0 = win.state.camera
    v = win.view3d
    qtbot.mousePress(v, Qt.LeftButton, pos=QPoint(60, 80))
    for x in (70, 80, 90, 100):
        qtbot.mouseMove(v, QPoint(x, 80))
    assert win.state.interacting
    qtbot.mouseRelease(v, Qt.LeftButton, pos=QPoint(100, 80))
    cam1 = win.state.camera
    turned = _angle(np.subtract(cam0.position, cam0.target), np.subtract(cam1.position, cam1.target))
    assert turned == pytest.approx(40 * DEGREES_PER_PIXEL, abs=1e-6)
    assert cam1.distance == pytest.approx(cam0.distance)
    assert win.wait_for_final(60)
    assert win.view3d.frame.camera == cam1  # the refined picture is of the new camera


def _drag(win, qtbot, timeout_ms):
    """Press, move and release on the 3-D view once a reduced frame came; the frames received, in order."""
    frames = []
    win.worker.frame_ready.connect(frames.append)
    v = win.view3d
    qtbot.mousePress(v, Qt.LeftButton, pos=QPoint(80, 80))
    qtbot.mouseMove(v, QPoint(90, 80))
    qtbot.waitUntil(lambda: any(not f.final for f in frames), timeout=timeout_ms)
    qtbot.mouseRelease(v, Qt.LeftButton, pos=QPoint(90, 80))
    return frames


def test_drag_gives_reduced_frames_then_the_refined_one(make_window, qtbot):
    win = make_window()
    frames = _drag(win, qtbot, 10000)
    assert win.wait_for_final(60)
    reduced = [f for f in frames if not f.final]
    assert reduced[0].fraction in (0.5, 0.25) and reduced[0].rgb.shape == (VIEW, VIEW, 3)
    assert frames[-1].final and frames[-1].fraction == 1.0


def test_key_j_adds_a_light_at_the_camera_and_changes_the_picture(make_window, qtbot):
    win = make_window()
    before = _rgb(win)
    cam = win.state.camera
    qtbot.keyClick(win.view3d, Qt.Key_J)
    assert len(win.state.scene.lights) == 1
    light = win.state.scene.lights[0]
    assert np.allclose(light.position, cam.position)
    assert np.allclose(light.direction, cam.basis()[2])
    assert win.state.scene.shading.mode == "phong" and win.state.selected_light == 0
    assert win.wait_for_final(60)
    diff = np.abs(_rgb(win) - before).max(axis=2)
    head = before.sum(axis=2) > 0
    assert diff.max() >= 10 and (diff[head] >= 3).mean() > 0.2  # the spot's falloff relights the head


def test_key_l_cycles_the_shading_models(make_window, qtbot):
    from volumen.core import SHADINGS

    win = make_window()
    start = win.state.scene.shading.mode
    qtbot.keyClick(win.view3d, Qt.Key_L)
    assert win.state.scene.shading.mode == SHADINGS[(SHADINGS.index(start) + 1) % len(SHADINGS)]


def test_preset_change_changes_the_picture(make_window):
    win = make_window()
    before = _rgb(win)
    win.tf_editor.presets.setCurrentText("ct-bone")  # the CT's default is ct-skin-bone
    win.tf_editor.presets.activated.emit(win.tf_editor.presets.currentIndex())
    assert win.state.scene.transfer.name == "ct-bone"
    assert win.wait_for_final(60)
    after = _rgb(win)
    assert np.abs(after - before).mean() > 5


def test_slice_views_scroll_link_and_window(make_window, qtbot, head64):
    win = make_window()
    ax, cor = win.slices["axial"], win.slices["coronal"]
    z0 = win.state.crosshair[2]
    i0 = ax.index
    QApplication.sendEvent(ax, QWheelEvent(QPointF(50, 50), QPointF(50, 50), QPoint(0, 0), QPoint(0, 120),
                                           Qt.NoButton, Qt.NoModifier, Qt.ScrollUpdate, False))
    assert ax.index == i0 + 1
    assert ax.geometry_.distance_to_slice(win.state.crosshair, i0 + 1) == pytest.approx(0.0, abs=1e-9)
    assert win.state.crosshair[2] - z0 == pytest.approx(head64.spacing[0], abs=0.5 * head64.spacing[0] + 1e-9)
    # a click in the coronal view moves the crosshair: the axial view follows
    r = cor.image_rect()
    qtbot.mouseClick(cor, Qt.LeftButton, pos=QPoint(int(r.center().x()), int(r.top() + r.height() * 0.2)))
    assert ax.index > i0 + 5  # clicked high up: a more superior axial slice
    w0 = win.state.window
    qtbot.mousePress(ax, Qt.RightButton, pos=QPoint(50, 50))
    qtbot.mouseMove(ax, QPoint(90, 30))
    qtbot.mouseRelease(ax, Qt.RightButton, pos=QPoint(90, 30))
    assert win.state.window.width > w0.width and win.state.window.level > w0.level


def test_corrupt_file_shows_an_error_and_keeps_the_data(make_window, qtbot, tmp_path):
    win = make_window()
    bad = tmp_path / "broken.nii"
    bad.write_bytes(b"\x00" * 100)
    volume = win.state.volume
    task = win.open_path(str(bad))
    qtbot.waitUntil(lambda: task.finished, timeout=20000)
    assert win.last_error is not None and "broken.nii" in win.last_error[1]
    boxes = [w for w in QApplication.topLevelWidgets() if isinstance(w, QMessageBox) and w.isVisible()]
    assert boxes and "broken.nii" in boxes[-1].text()
    for b in boxes:
        b.close()
    assert win.state.volume is volume and win.view3d.frame is not None


def test_opening_a_file_the_reader_warned_of_says_so_in_the_status_bar(make_window, qtbot, tmp_path):
    """A 4-D NIfTI holding NaN opens (its first volume, the NaN as 0) and the status bar says the first of the
    reader's two warnings, as ``volumen`` commands say them on the terminal; no error dialog."""
    import nibabel as nib

    data = np.random.default_rng(2).random((12, 12, 12, 2)).astype(np.float32)
    data[0, 0, 0, 0] = np.nan
    nib.save(nib.Nifti1Image(data, np.eye(4)), tmp_path / "dwi.nii.gz")
    win = make_window()
    _settle_device(win, qtbot)  # its own status message comes first
    task = win.open_path(str(tmp_path / "dwi.nii.gz"))
    qtbot.waitUntil(lambda: task.finished and win.state.volume.shape == (12, 12, 12), timeout=20000)
    assert len(win.load_warnings) == 2 and "first volume" in win.load_warnings[0] and "NaN" in win.load_warnings[1]
    assert win.statusBar().currentMessage() == f"Warning: {win.load_warnings[0]} (2 in all)"
    assert win.last_error is None


def _settle_device(win, qtbot):
    """Wait for the worker's OpenGL probe to answer and the view to take its device (``device_reason`` set).
    The probe runs on the process's one OpenGL thread, behind the frames other windows queued there (slow on
    llvmpipe while kernels compile), hence the long timeout."""
    qtbot.waitUntil(lambda: win.device_reason is not None, timeout=120000)


def test_3d_view_takes_the_fastest_device_and_says_why(make_window, qtbot):
    """OpenGL on a software rasterizer (Mesa's llvmpipe without a GPU, as here) is slower than the CPU ray
    caster: the view stays on the CPU and says so; a hardware renderer takes the view to gl."""
    from volumen.render.raster import RasterUnavailable, gl_renderer

    win = make_window()
    _settle_device(win, qtbot)
    try:
        renderer, hardware = gl_renderer()
    except RasterUnavailable as exc:
        renderer, hardware = str(exc), False
    print(f"renderer {renderer!r}: {win.device_reason}")
    assert win.state.device == ("gl" if hardware else "cpu")
    assert renderer.split()[0] in win.device_reason
    assert ("hardware" in win.device_reason) == hardware


def test_saved_session_reproduces_the_picture_in_a_new_window(make_window, tmp_path, head64):
    import dataclasses

    from volumen.app._view_picture import render_frame
    from volumen.core import ClipPlane

    win = make_window()
    win.tf_editor.apply_preset("ct-skin-bone")
    win.state.set_camera(win.state.camera.with_(position=tuple(np.add(win.state.camera.position, (200, 0, 100)))))
    from volumen.app._light_panel import add_light_at_camera

    add_light_at_camera(win.state)
    win.clip_panel.add_plane(0)
    win.state.set_display(brightness=1.3)
    assert win.wait_for_final(60)
    first = _rgb(win)
    path = tmp_path / "session.json"
    win.save_session(path)
    assert win.last_error is None

    other = make_window(load=False)
    assert other.load_session(path, volume=head64)
    assert other.wait_for_final(60)
    assert isinstance(other.state.scene.clipping.planes[0], ClipPlane)
    assert other.state.scene == win.state.scene and other.state.camera == win.state.camera
    # the first window's picture drawn where the new window drew its own (a window starts on the CPU and takes
    # gl once the worker's OpenGL probe answers; the two devices differ by a grey level)
    device = other.view3d.frame.stats["renderer"]["device"]
    if device != win.view3d.frame.stats["renderer"]["device"]:
        first = render_frame(dataclasses.replace(win.frame_job(), device=device)).rgb.astype(int)
    assert np.abs(_rgb(other) - first).max() <= 1


def test_interface_answers_within_100_ms_during_a_slow_render(make_window, qtbot):
    """Input is handled within 100 ms during a slow render. What makes that true is structural
    (rendering happens off the GUI thread) and is asserted strictly: every event is handled while the render
    is still running. The latency itself is machine-dependent, so the 100 ms bound applies to the median of
    five events (one scheduler hiccup on a loaded CI machine must not decide it); all delays are printed."""
    from dataclasses import replace

    win = make_window()
    st = win.state
    # a slow picture: path tracing refining toward 4096 samples per pixel at 480x480 (seconds of work)
    st.update_scene(shading=replace(st.scene.shading, mode="pathtrace", pt_samples=4096))
    win.view3d.setFixedSize(480, 480)  # a slow picture
    qtbot.waitUntil(lambda: not win.worker.idle, timeout=5000)
    ax = win.slices["axial"]
    delays = []
    for _ in range(5):
        i0 = ax.index
        t = time.perf_counter()
        QApplication.postEvent(ax, QWheelEvent(QPointF(50, 50), QPointF(50, 50), QPoint(0, 0), QPoint(0, 120),
                                               Qt.NoButton, Qt.NoModifier, Qt.ScrollUpdate, False))
        qtbot.waitUntil(lambda i0=i0: ax.index == i0 + 1, timeout=2000)
        delays.append(time.perf_counter() - t)
        qtbot.wait(20)
    assert not win.worker.idle, "the render finished before the events were handled: make it slower"
    print("event delays during the render (ms):", [round(d * 1000, 1) for d in delays])
    assert sorted(delays)[len(delays) // 2] < 0.1, delays


def test_cli_api_and_app_share_the_device_and_technique_names(qtbot):
    """The app's boxes, the command line's choices and the API's checks all read volumen.render's one
    declaration of devices, techniques and technique options."""
    import argparse

    from volumen.app._render_panel import RenderPanel
    from volumen.app._state import AppState
    from volumen.cli._render import register
    from volumen.render import DEVICES, Technique, option_choices, resolve_device

    def texts(box):
        return [box.itemText(i) for i in range(box.count())]

    panel = RenderPanel(AppState())
    qtbot.addWidget(panel)
    assert texts(panel.technique) == list(TECHNIQUES) and texts(panel.device) == list(DEVICES)
    flags = {a.dest: a for a in register(argparse.ArgumentParser().add_subparsers())._actions}
    assert list(flags["device"].choices) == list(DEVICES) and list(flags["technique"].choices) == list(TECHNIQUES)
    for name in TECHNIQUES:
        for field, choices in option_choices(name).items():
            assert flags[f"{name}_{field}"].option_strings[0] == f"--{name}-{field.replace('_', '-')}"
            if isinstance(choices, tuple):
                assert list(flags[f"{name}_{field}"].choices) == list(choices)
                assert texts(panel.options[(name, field)]) == list(choices)
                assert getattr(Technique(name, **{field: choices[-1]}).options, field) == choices[-1]
    usable = []  # the devices the API accepts for ray casting are the ones the app enables for it
    for device in DEVICES:
        try:
            resolve_device(device, "raycast")
        except ValueError:
            continue
        usable.append(device)
    enabled = [d for i, d in enumerate(DEVICES) if panel.device.model().item(i).isEnabled()]
    assert panel.state.technique.name == "raycast" and usable == ["cpu", "cuda", "gl", "auto"]
    assert enabled == ["cpu", "cuda", "auto"]  # gl is enabled once the render worker has found OpenGL
    with pytest.raises(ValueError, match="valid: cpu, cuda, gl, auto"):
        resolve_device("opengl")


def test_every_technique_and_mode_draws_a_picture(make_window):
    """Walk the technique box (OpenGL ones when the worker found OpenGL), a choice option of each, and the
    modes of volumen.core.MODES."""
    from volumen.core import MODES

    win = make_window()
    panel = win.render_panel
    pictures = {}
    for row in range(panel.technique.count()):
        name, item = panel.technique.itemData(row), panel.technique.model().item(row)
        if not item.isEnabled():
            assert item.toolTip()  # disabled, with the reason
            print(f"technique {name!r} skipped: {item.toolTip()}")
            continue
        panel.technique.setCurrentIndex(row)
        assert win.state.technique.name == name and win.state.device in TECHNIQUES[name].devices
        assert win.wait_for_final(60) and win.last_error is None, win.last_error
        pictures[name] = _rgb(win)
        assert pictures[name].sum(axis=2).astype(bool).mean() > 0.1, name
        for (tech, field), box in panel.options.items():
            if tech == name:  # the last value of each choice option, through its box
                box.setCurrentIndex(box.count() - 1)
                assert getattr(win.state.technique.options, field) == box.currentText()
        assert win.wait_for_final(60) and win.last_error is None, win.last_error
    panel.technique.setCurrentIndex(panel.technique.findData("raycast"))
    gl_ok = panel.technique.model().item(panel.technique.findData("slicing")).isEnabled()
    assert win.state.device == ("gl" if gl_ok else "cpu")  # the modes below: the 3-D view's OpenGL ray caster
    for mode in MODES:
        win.state.update_scene(mode=mode)
        assert win.wait_for_final(60) and win.last_error is None, win.last_error
        pictures[mode] = _rgb(win)
    print("pictures of", sorted(pictures))
    assert np.abs(pictures["mip"] - pictures["composite"]).mean() > 5


def test_3d_view_ray_casts_on_gl_with_a_reduced_drag(make_window, qtbot):
    """The 3-D view on ``gl`` (chosen by the user where OpenGL is a software renderer, as llvmpipe here):
    reduced frames while dragging, then the refined one, each drawn by the gl device; the final picture equals
    the CPU's (mean |RGB diff| <= 2 of 255)."""
    import dataclasses

    from volumen.app._view_picture import render_frame

    win = make_window()
    _settle_device(win, qtbot)
    ok, reason = win.render_panel._raster
    if not ok:
        print(f"skipped: no OpenGL here ({reason})")
        pytest.skip(f"no OpenGL context: {reason}")
    win.state.set_display(device="gl")
    assert win.wait_for_final(120)  # the first gl picture (its shaders compiled on llvmpipe) before the drag
    frames = []
    win.worker.frame_ready.connect(frames.append)
    v = win.view3d
    qtbot.mousePress(v, Qt.LeftButton, pos=QPoint(80, 80))
    qtbot.mouseMove(v, QPoint(95, 85))
    qtbot.waitUntil(lambda: any(not f.final for f in frames), timeout=10000)
    qtbot.mouseRelease(v, Qt.LeftButton, pos=QPoint(95, 85))
    assert win.wait_for_final(60)
    reduced = [f for f in frames if not f.final]
    assert reduced[0].fraction in (0.5, 0.25) and reduced[0].stats["renderer"]["device"] == "gl"
    final = frames[-1]
    assert final.final and final.stats["renderer"]["device"] == "gl"
    cpu = render_frame(dataclasses.replace(win.frame_job(), device="cpu", camera=final.camera))
    assert np.abs(cpu.rgb.astype(float) - final.rgb.astype(float)).mean() <= 2.0


def test_chunked_volume_drags_at_a_coarse_level_and_refines_to_the_full_one(make_window, qtbot, tmp_path):
    """An OME-Zarr of 96 x 128 x 128 (levels 128, 64, 32 voxels on the long side) in the 160 px view: frames
    during a drag come from a coarser level (the reduced viewport's side is 80 or 40 px: level 1 or 2, about
    one voxel per pixel), the refined frame after the release from level 0."""
    pytest.importorskip("zarr", reason="the scale extra (zarr) is not installed")
    import volumen
    from volumen.scale import write_synthetic

    path = tmp_path / "s.ome.zarr"
    write_synthetic(path, (96, 128, 128), chunks=32)
    win = make_window(load=False)
    win.set_volume(volumen.load(path), str(path))
    assert win.wait_for_final(120)
    assert win.view3d.frame.stats["level"] == 0
    frames = _drag(win, qtbot, 60000)
    assert win.wait_for_final(120)
    reduced = [f for f in frames if not f.final]
    expected = {0.5: 1, 0.25: 2}[reduced[0].fraction]
    assert reduced[0].stats["level"] == expected and reduced[0].rgb.shape == (VIEW, VIEW, 3)
    assert frames[-1].final and frames[-1].stats["level"] == 0
    assert frames[-1].rgb.any()
