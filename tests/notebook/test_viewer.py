"""The notebook viewer driven without a browser: drags, controls, the frame it sends, scene and camera."""

from __future__ import annotations

import asyncio
import io

import numpy as np
import pytest
from PIL import Image as PILImage

from volumen.core import Camera, TransferFunction, gestures
from volumen.notebook import REDUCED_FRACTION
from volumen.render import render


def _angle(a, b) -> float:
    a, b = np.asarray(a, float), np.asarray(b, float)
    return float(np.degrees(np.arccos(np.clip(a @ b / np.linalg.norm(a) / np.linalg.norm(b), -1, 1))))


def _drag(canvas, points, button=1, modifiers=()):
    (x0, y0), *rest = points
    canvas.handle_event({"type": "pointer_down", "x": x0, "y": y0, "button": button, "modifiers": modifiers})
    for x, y in rest:
        canvas.handle_event({"type": "pointer_move", "x": x, "y": y, "button": button, "modifiers": modifiers})
    canvas.handle_event({"type": "pointer_up", "x": rest[-1][0], "y": rest[-1][1], "button": button,
                         "modifiers": modifiers})


def test_drag_turns_the_camera_as_the_desktop_app_does(viewer):
    """The desktop app's test drags 40 px in four moves and expects 40 * DEGREES_PER_PIXEL; so do we,
    and the camera equals gestures.orbit applied to the same moves (the app's function)."""
    cam0 = viewer.camera
    fractions = []
    deliver = viewer.view._deliver
    viewer.view._loop._deliver = lambda frame, req: (fractions.append(req.fraction), deliver(frame, req))
    _drag(viewer.canvas, [(60, 80), (70, 80), (80, 80), (90, 80), (100, 80)])
    cam1 = viewer.camera
    expected = cam0
    for _ in range(4):
        expected = gestures.orbit(expected, 10, 0)
    assert _angle(np.subtract(cam0.position, cam0.target), np.subtract(cam1.position, cam1.target)) == \
        pytest.approx(40 * gestures.DEGREES_PER_PIXEL, abs=1e-6)
    np.testing.assert_allclose(cam1.position, expected.position, atol=1e-9)
    np.testing.assert_allclose(cam1.up, expected.up, atol=1e-9)
    assert viewer.wait(60)
    assert fractions[-1] == 1.0 and viewer.view.frame_state.camera == cam1  # refined picture of the new camera
    assert REDUCED_FRACTION in fractions or len(fractions) == 1  # drag frames were reduced (unless all skipped)


def test_shift_drag_pans_and_wheel_zooms_as_in_the_app(viewer, view_size):
    cam0 = viewer.camera
    _drag(viewer.canvas, [(10, 10), (30, 20)], modifiers=("Shift",))
    assert viewer.camera == gestures.pan(cam0, 20, 10, view_size)
    cam1 = viewer.camera
    viewer.canvas.handle_event({"type": "wheel", "x": 5, "y": 5, "dx": 0, "dy": -100, "modifiers": ()})
    assert viewer.camera == gestures.wheel_zoom(cam1, 1)  # one notch toward the scene, as the app's wheel
    cam2 = viewer.camera
    _drag(viewer.canvas, [(10, 40), (10, 20)], button=2)  # right drag up: closer, as in the app
    assert viewer.camera == gestures.drag_zoom(cam2, -20)
    assert viewer.camera.distance == pytest.approx(cam2.distance / np.exp(0.2), rel=1e-9)


def test_a_preset_change_renders_the_new_transfer_function(viewer, head32, view_size):
    before = viewer.frame.copy()
    viewer.controls.preset.value = "ct-bone"
    assert viewer.wait(60)
    tf = TransferFunction.preset("ct-bone", value_range=head32.value_range())
    assert viewer.scene.transfer == tf
    assert viewer.view.frame_state.scene.transfer == tf
    expected = render(viewer.scene, viewer.camera, view_size).to_uint8()
    assert np.abs(viewer.frame.astype(int) - expected).max() <= 1
    assert np.abs(before.astype(int) - expected).mean() > 1.0  # it really changed the picture


def test_controls_write_mode_shading_lights_and_clipping(viewer, head32):
    c = viewer.controls
    c.mode.value = "mip"
    c.shading.value = "phong"
    c.add_light.click()
    c.crop[0].value = (4, 20)
    s = viewer.scene
    assert (s.mode, s.shading.mode, len(s.lights)) == ("mip", "phong", 1)
    assert s.lights[0].position == pytest.approx(viewer.camera.position)
    nz, ny, nx = head32.shape
    assert s.clipping.crop == (4, 20, 0, ny - 1, 0, nz - 1)
    c.clear_lights.click()
    assert viewer.scene.lights == ()
    assert viewer.wait(60) and viewer.view.frame_state.scene == viewer.scene


def test_scene_and_camera_are_settable_from_python(viewer, head32):
    cam = Camera.anatomical(head32, "left")
    viewer.camera = cam
    viewer.scene = viewer.scene.with_(mode="mip")
    assert viewer.controls.mode.value == "mip"  # the controls follow
    assert viewer.wait(60)
    assert viewer.view.frame_state.camera == cam and viewer.view.frame_state.scene.mode == "mip"
    assert Camera.from_json(viewer.camera.to_json()) == cam  # what `volumen render --camera` reads
    with pytest.raises(ValueError, match="Camera"):
        viewer.camera = "left"


def test_the_frame_sent_equals_volumen_render_of_the_scene_and_camera(scene, view_size):
    """In a running event loop (as in a kernel) the canvas sends the background thread's frame; decoded
    (lossless PNG at quality 100) it equals volumen.render of the viewer's scene and camera within 1/255."""
    from volumen.notebook._widget import Viewer

    async def run():
        w = Viewer(scene, Camera.orbit(scene.volume, azimuth=30), view_size, slices=False)
        w.canvas.quality = 100
        sent = []
        w.canvas.send = lambda msg, buffers=None: sent.append((msg, buffers))
        w.canvas._has_visible_views = True
        for _ in range(3000):
            if sent and w.view.final:
                break
            await asyncio.sleep(0.1)
        w.close()
        return w, sent

    w, sent = asyncio.run(run())
    msg, buffers = sent[-1]
    assert msg["type"] == "framebufferdata" and msg["mimetype"] == "image/png"
    got = np.asarray(PILImage.open(io.BytesIO(bytes(buffers[0]))).convert("RGB"))
    expected = render(w.scene, w.camera, view_size).to_uint8()
    assert got.shape == expected.shape
    assert np.abs(got.astype(int) - expected).max() <= 1
    assert (expected.max(axis=2) > 0).mean() > 0.1  # a picture, not an empty frame


def test_a_volume_opens_as_the_command_line_draws_it():
    """``volumen.show`` of a volume picks what ``volumen render`` picks with no flags: a single CT slice as its
    MIP, a colour ultrasound frame composited opaque and unshaded, a whole volume composited under the headlight
    (before, every volume was composited under the headlight)."""
    from pydicom.data import get_testdata_file

    import volumen
    from volumen.data import phantom
    from volumen.render import default_transfer

    cases = ((volumen.load(get_testdata_file("CT_small.dcm")), "mip", "headlight"),
             (volumen.load(get_testdata_file("examples_rgb_color.dcm")), "composite", "none"),
             (phantom("head", size=(24, 24, 24)), "composite", "headlight"))
    for vol, mode, shading in cases:
        v = volumen.show(vol, size=(64, 64), slices=False)
        try:
            assert (v.scene.mode, v.scene.shading.mode) == (mode, shading)
            assert v.scene.transfer == default_transfer(vol, mode)
            assert (v.scene.transfer.name == "mip-gray") == (mode == "mip" or vol.is_color)  # the frame's: opaque
        finally:
            v.close()
