"""The application's Qt-free parts: gestures, overlays, slice geometry, stereo, sessions, transfer editing."""

from __future__ import annotations

import json
import os

import numpy as np
import pytest

from volumen.core import Camera, Light, TransferFunction, canonical, slice_at


def _angle(a, b) -> float:
    a, b = np.asarray(a, float), np.asarray(b, float)
    return float(np.degrees(np.arccos(np.clip(a @ b / np.linalg.norm(a) / np.linalg.norm(b), -1, 1))))


def test_orbit_turns_by_degrees_per_pixel_and_keeps_the_distance(head64):
    from volumen.core.gestures import DEGREES_PER_PIXEL, orbit

    cam = Camera.anatomical(head64, "anterior")
    back0 = np.subtract(cam.position, cam.target)
    new = orbit(cam, 40, 0)
    back1 = np.subtract(new.position, new.target)
    assert _angle(back0, back1) == pytest.approx(40 * DEGREES_PER_PIXEL, abs=1e-9)
    assert new.distance == pytest.approx(cam.distance, rel=1e-12)
    # dragging right turns the head to its left side toward us: the eye moves toward the patient's right (+x)
    assert back1[0] > 0
    up = orbit(cam, 0, -30)  # drag up: the head's front turns up, the eye goes below it (object follows mouse)
    assert _angle(back0, np.subtract(up.position, up.target)) == pytest.approx(15.0, abs=1e-9)
    assert up.position[2] < cam.position[2]


def test_pan_moves_the_target_by_the_pixel_size_and_zoom_divides_the_distance(head64):
    from volumen.core.gestures import mm_per_pixel, pan, zoom

    cam = Camera.anatomical(head64, "anterior")
    s = mm_per_pixel(cam, (200, 200))
    moved = pan(cam, 10, 0, (200, 200))
    r = cam.basis()[0]
    assert np.allclose(np.subtract(moved.target, cam.target), -10 * s * r)
    assert zoom(cam, 2.0).distance == pytest.approx(cam.distance / 2)


def test_light_moves_in_the_view_plane_and_the_cone_apex_is_its_projection(head64):
    from volumen.app._overlays import light_cone, pick_light
    from volumen.core.gestures import aim_light, light_at_camera, move_light

    cam = Camera.anatomical(head64, "anterior")
    light = Light(position=tuple(np.add(cam.target, (0, 60, 0))), direction=(0, -1, 0), exponent=5)
    size = (160, 160)
    cone = light_cone(light, cam, size, 20.0)
    apex, _ = cam.project(light.position, size)
    assert cone.visible and np.allclose(cone.apex, apex)
    moved = move_light(light, cam, 10, 0, size)
    new_apex, _ = cam.project(moved.position, size)
    assert np.allclose(new_apex - apex, (10, 0), atol=1e-6)  # follows the mouse at its own depth
    assert pick_light([light], cam, size, 20.0, apex + 2) == 0
    assert pick_light([light], cam, size, 20.0, apex + 40) is None
    aimed = aim_light(light, cam, 20, 0)
    assert _angle(light.direction, aimed.direction) == pytest.approx(10.0, abs=1e-9)
    j = light_at_camera(cam)
    assert np.allclose(j.position, cam.position) and np.allclose(j.direction, cam.basis()[2])


def test_slice_geometry_matches_slice_at(head64):
    from volumen.app._slice_geometry import SliceGeometry

    can = canonical(head64)
    rng = np.random.default_rng(1)
    for plane in ("axial", "coronal", "sagittal"):
        g = SliceGeometry(can, plane)
        for _ in range(5):
            ijk = np.array([rng.integers(0, n) for n in can.shape[::-1]], float)
            world = can.index_to_world(ijk)
            index = g.index_of(world)
            img, _ = slice_at(head64, plane, index=index)
            col, row = g.world_to_display(world)
            assert img[int(row), int(col)] == can.data[int(ijk[2]), int(ijk[1]), int(ijk[0])]
            assert np.allclose(g.display_to_world(col, row, index), world)
    # radiological orientation: the patient's right (+x) on the left of the axial view, anterior at the top
    g = SliceGeometry(can, "axial")
    c = np.asarray(head64.center)
    right, front = g.world_to_display(c + (50, 0, 0)), g.world_to_display(c + (0, 50, 0))
    centre = g.world_to_display(c)
    assert right[0] < centre[0] and front[1] < centre[1]


def test_stereo_eyes_are_separated_and_converge(head64):
    from volumen.app._stereo import Stereo, combine, eye_cameras, eye_size

    cam = Camera.anatomical(head64, "anterior")
    st = Stereo(mode="side-by-side", eye_separation=30.0)
    left, right = eye_cameras(cam, st)
    assert np.linalg.norm(np.subtract(left.position, right.position)) == pytest.approx(30.0)
    assert np.allclose(left.target, right.target) and np.allclose(left.target, cam.target)
    assert eye_size((160, 100), st) == (80, 100)
    a = np.full((100, 80, 3), 10, np.uint8)
    b = np.full((100, 80, 3), 200, np.uint8)
    out = combine([a, b], st, (160, 100))
    assert out.shape == (100, 160, 3) and out[0, 0, 0] == 10 and out[0, -1, 0] == 200
    ana = combine([a, b], Stereo(mode="anaglyph"), (80, 100))
    assert tuple(ana[0, 0]) == (10, 200, 200)
    with pytest.raises(ValueError, match="stereo mode"):
        Stereo(mode="3d")


def test_transfer_edits_keep_points_ordered():
    from volumen.app import _tf_edit as edit

    tf = TransferFunction(color=((0, 0, 0, 0), (50, 1, 0, 0), (100, 1, 1, 1)), opacity=((0, 0), (50, 0.5), (100, 1)))
    moved = edit.move_opacity_point(tf, 1, 500.0, 2.0)
    assert moved.opacity[1] == (100.0, 1.0)  # clamped to the next point and to alpha 1
    added, i = edit.add_opacity_point(tf, 25.0, 0.2)
    assert i == 1 and added.opacity[1] == (25.0, 0.2)
    assert len(edit.remove_opacity_point(tf, 1).opacity) == 2
    assert edit.set_color_stop(tf, 1, (0, 0, 1)).color[1] == (50.0, 0.0, 0.0, 1.0)
    heights, edges = edit.log_histogram(__import__("volumen.data", fromlist=["phantom"]).phantom("sphere", size=16))
    assert heights.max() == pytest.approx(1.0) and len(edges) == len(heights) + 1


def test_session_file_is_written_atomically_and_checked(tmp_path, head64):
    from volumen.app._session import SessionError, load_session, save_session, session_dict, write_atomic
    from volumen.app._state import AppState

    st = AppState()
    st.set_volume(head64, "phantom:head?size=64")
    path = tmp_path / "s.json"
    save_session(path, session_dict(st, (160, 160)))
    d = load_session(path)
    assert d["scene"]["volume"] == "phantom:head?size=64" and d["size"] == [160, 160]
    assert [p.name for p in tmp_path.iterdir()] == ["s.json"]  # no temporary file left
    # a failing write leaves the old file whole
    before = path.read_text()

    with pytest.raises(TypeError):
        write_atomic(path, 12345)  # not text: fails while writing the temporary file
    assert path.read_text() == before and len(os.listdir(tmp_path)) == 1
    path.write_text(json.dumps({"version": 99}))
    with pytest.raises(SessionError, match="not a volumen session"):
        load_session(path)
    path.write_text("{nope")
    with pytest.raises(SessionError, match="JSON"):
        load_session(path)


def test_session_keeps_device_and_technique_and_reads_old_backend_names(tmp_path, head64):
    """A session records the device and the technique with its options as ``volumen render --save-settings``
    does (top-level ``device``, ``technique``); a session of volumen 0.1 (``app.technique = "mesh-gouraud"``)
    still opens."""
    from volumen.app._session import apply_session, session_dict
    from volumen.app._state import AppState
    from volumen.render import Technique

    st = AppState()
    st.set_volume(head64, "phantom:head?size=64")
    st.set_display(technique=Technique("slicing", planes="two-then-one", precision="float16"))
    assert st.device == "gl"  # the technique's default device, as cpu is not one of its devices
    d = json.loads(json.dumps(session_dict(st, (64, 64))))
    assert d["device"] == "gl" and d["technique"]["options"]["planes"] == "two-then-one"
    again = AppState()
    apply_session(again, d, head64)
    assert (again.device, again.technique) == (st.device, st.technique)
    old = {k: v for k, v in d.items() if k not in ("device", "technique")}
    old["app"] = dict(d["app"], technique="mesh-gouraud")
    apply_session(again, old, head64)
    assert (again.device, again.technique) == ("gl", Technique("mesh", shading="gouraud"))


def test_a_picture_finishing_after_stop_is_dropped_not_emitted(qtbot, monkeypatch):
    """A first picture compiles for longer than ``stop`` waits; when it finishes, its window (and the worker)
    may be gone. It used to emit into the deleted worker: "Signal source has been deleted" in the render
    thread. Now nothing is emitted after ``stop`` and the thread ends quietly."""
    import threading

    import shiboken6

    from volumen.app import _worker

    started, release, errors = threading.Event(), threading.Event(), []

    def slow_picture(job, fraction, final=True):
        started.set()
        release.wait(5)
        return "frame"

    monkeypatch.setattr(_worker, "render_frame", slow_picture)
    monkeypatch.setattr(_worker.RenderWorker, "_probe_raster", lambda self: None)
    monkeypatch.setattr(threading, "excepthook", lambda args: errors.append(args.exc_value))
    worker = _worker.RenderWorker()
    got = []
    worker.frame_ready.connect(got.append)
    worker.start()
    worker.submit(None, interactive=True)
    assert started.wait(5)
    worker.stop(timeout=0.01)  # the picture outlives the wait
    thread = worker._thread
    shiboken6.delete(worker)  # the window closed: Qt deleted its worker
    release.set()
    thread.join(5)
    assert not thread.is_alive() and errors == [] and got == []


def test_the_transfer_function_editor_spans_the_table_range_not_a_fill(qtbot):
    """The editor's plot (and its histogram) spans ``core.table_range``: for an MRI filled with -1e6 outside its
    field of view the table's, not -1e6 onward, where the tissue's whole range was 1/1600 of the plot's width."""
    from volumen.app._tf_editor import TransferCanvas
    from volumen.core import table_range
    from volumen.data import fill_outside_field, phantom

    vol = fill_outside_field(phantom("mr_head", size=32, dtype="float32"), -1e6)

    class State:
        volume = vol

        def subscribe(self, *args):
            pass

    canvas = TransferCanvas(State())
    qtbot.addWidget(canvas)
    assert canvas.range == table_range(vol) and canvas.range[0] > -2e4
    heights, edges = canvas._hist
    assert edges[0] == pytest.approx(canvas.range[0], rel=1e-6) and np.count_nonzero(heights[edges[:-1] >= 0]) >= 5
