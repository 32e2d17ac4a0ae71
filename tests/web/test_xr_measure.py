"""The ruler in the emulated headset (iwer over headless Chromium): B on the right controller picks the first
visible surface along its ray, as ``volumen.measure.pick`` does along the same ray computed here from the
controller's pose and the page's placement (within a voxel); two picks make a ruler, drawn in each eye's
picture where ``Camera.project`` puts its ends for that eye, with its length beside it."""

from __future__ import annotations

import numpy as np
from PIL import Image

from tests.web.test_xr import EYE, HEAD0, _button, _model, _set, xr_browser  # noqa: F401 - registers the headset fixture
from tests.web.web_helpers import picture, reference_scenes, scene_json
from volumen import measure
from volumen.core import Camera, Scene


def _aim(direction) -> list[float]:
    """The quaternion (x, y, z, w) turning a controller's ray (its -z) onto ``direction``."""
    a, b = np.array([0.0, 0.0, -1.0]), np.asarray(direction, float) / np.linalg.norm(direction)
    axis, c = np.cross(a, b), float(a @ b)
    q = np.r_[axis, 1.0 + c]
    return list(q / np.linalg.norm(q))


def test_the_controller_draws_a_ruler_between_two_picked_points(request, head_server, output_dir):
    b = request.getfixturevalue("xr_browser")
    served = head_server.handlers.served().volume
    scene, cam, _ = reference_scenes.scenes()["head/composite/headlight"]
    scene = scene.with_(volume=served)
    b.evaluate(f"volumen.show({{scene: {scene_json(scene)}, camera: {cam.to_json()}}})")
    if not b.evaluate("volumen.xr.session !== null"):
        b.evaluate("volumen.enterVR({governor: false})")
    model = _model(b.evaluate("volumen.stateVR()"))
    inv = np.linalg.inv(model)
    ctrl = "iwerDevice.controllers.right"
    hand = np.array([0.05, -0.15, -0.2])  # the controller, in the 'local' space (m)
    centre = (model @ np.r_[served.center, 1.0])[:3]
    expected = []
    page_scene = Scene.from_dict({**b.evaluate("volumen.viewer.scene"), "volume": ""}, volume=served)
    for offset in ([-0.04, 0.02, 0.0], [0.05, -0.01, 0.0]):
        direction = centre + offset - hand
        _set(b, ctrl, hand + HEAD0, _aim(direction))
        _button(b, ctrl, "b-button", 1, 1, 1)
        _button(b, ctrl, "b-button", 0, 0, 1)
        b.evaluate("volumen.ruler3d.picking")
        origin = (inv @ np.r_[hand, 1.0])[:3]  # the ray in volume mm
        ahead = (inv @ np.r_[direction, 0.0])[:3]
        ahead /= np.linalg.norm(ahead)
        up = (0, 0, 1) if abs(ahead[2]) < 0.9 else (0, 1, 0)
        along = Camera(position=tuple(origin), target=tuple(origin + ahead), up=up)
        expected.append(measure.pick(page_scene, along, (1, 1), 0.5, 0.5))
    (d,) = b.evaluate("volumen.measurements()")["measurements"]
    ruler = measure.from_dict(d)
    for got, want in zip((ruler.start, ruler.end), expected, strict=True):
        assert want is not None and np.linalg.norm(np.subtract(got, want)) < max(served.spacing)

    shots = b.evaluate("volumen.captureVR()")
    drawn = b.evaluate("volumen.xrRuler.drawn")
    both = np.hstack([picture(s["rgba"], EYE, EYE) for s in shots])
    Image.fromarray(np.rint(both[..., :3] * 255).astype(np.uint8)).resize((8 * EYE, 4 * EYE), Image.NEAREST).save(
        output_dir / "web_xr_ruler.png")  # both eyes, enlarged: worth a look
    for s in shots:
        (line,) = drawn[s["eye"]]
        assert line["text"] == f"{ruler.mm:.1f} mm"
        eye = Camera.from_dict(s["camera"])
        ends, _ = eye.project(np.array([ruler.start, ruler.end]), (EYE, EYE))
        assert np.allclose(line["ends"], ends, atol=1.0), s["eye"]  # the emulator's eyes are on axis
        rgba = picture(s["rgba"], EYE, EYE)
        x, y = np.clip(np.rint(ends.mean(axis=0)).astype(int), 0, EYE - 1)
        patch = np.rint(rgba[max(y - 1, 0):y + 2, max(x - 1, 0):x + 2, :3] * 255).reshape(-1, 3).astype(int)
        assert any(r > 230 and g > 210 and bl < 90 for r, g, bl in patch), (s["eye"], patch)  # the ruler's yellow
