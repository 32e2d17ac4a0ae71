"""The page in an emulated headset: iwer (the Immersive Web Emulation Runtime, a Meta Quest 3 with stereo
views) over headless Chromium. Each eye's picture equals the CPU's from that eye's pose and projection
(through the display transform: tone mapped, both eyes with the exposure metered on the first), computed here
from the emulator's head pose, interpupillary distance and field of view (not read from the page); a
controller with its trigger pressed places a spot light where it is (dragged to where it is released) and the
next frame is the CPU's picture with that light; a grab turned through a known rotation turns the volume by
it (+- 1 degree)."""

from __future__ import annotations

import numpy as np
import pytest

from tests.web.web_helpers import (
    DISPLAY_MEAN_TOL,
    DISPLAY_P99_TOL,
    EXPOSURE_TOL,
    compare,
    displayed,
    picture,
    reference_scenes,
    save_pair,
    scene_json,
)
from volumen.core import Camera, Display, Light
from volumen.render import render

EYE = 56                     # pixels of each eye's picture (the emulator's layer: the window's size)
HEAD0 = np.array([0.0, 1.6, 0.0])   # where the emulator's head starts: the origin of the 'local' space


@pytest.fixture(scope="module")
def xr_browser(chromium, iwer_source, head_server):
    from volumen.web import Chromium

    with Chromium((2 * EYE, EYE)) as b:
        b.add_script(iwer_source + "\n;window.iwerDevice = new IWER.XRDevice(IWER.metaQuest3);"
                     "iwerDevice.stereoEnabled = true; iwerDevice.installRuntime({forceInstall: true});")
        b.set_size(2 * EYE, EYE)
        b.open(head_server.url)
        yield b


def _quat(axis, degrees) -> np.ndarray:
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    h = np.radians(degrees) / 2
    return np.r_[a * np.sin(h), np.cos(h)]   # (x, y, z, w)


def _rot(q) -> np.ndarray:
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def _pose(position, q) -> np.ndarray:
    m = np.eye(4)
    m[:3, :3], m[:3, 3] = _rot(q), position
    return m


def _model(state) -> np.ndarray:
    return np.asarray(state["model"], float).reshape(4, 4).T   # column-major from the page


def _set(browser, what: str, position, q) -> None:
    browser.evaluate(f"(() => {{ const d = {what}; d.position.set({', '.join(map(str, position))}); "
                     f"d.quaternion.set({', '.join(map(str, q))}); }})()")


def _button(browser, ctrl: str, button: str, value: float, before: int, after: int) -> None:
    """After ``before`` XR frames set the controller's button, then wait ``after`` frames."""
    browser.evaluate(f"volumen.framesVR({before}).then(() => {ctrl}.updateButtonValue('{button}', {value}))"
                     f".then(() => volumen.framesVR({after}))")


def eye_cameras(model, head_position, head_q, ipd, fovy) -> dict:
    """The two eyes as Cameras in volume mm: the emulator's head pose (global), the eyes ``ipd / 2`` either
    side along the head's x axis, seen through the inverse of the page's placement ``model``."""
    local = _pose(np.asarray(head_position) - HEAD0, head_q)
    inv = np.linalg.inv(model)
    out = {}
    for eye, dx in (("left", -ipd / 2), ("right", ipd / 2)):
        e = inv @ local @ _pose([dx, 0, 0], [0, 0, 0, 1])
        pos, right, up = e[:3, 3], e[:3, 0] / np.linalg.norm(e[:3, 0]), e[:3, 1] / np.linalg.norm(e[:3, 1])
        fwd = -e[:3, 2] / np.linalg.norm(e[:3, 2])
        assert np.allclose(np.cross(fwd, up), right, atol=1e-9), "the placement mirrors the volume"
        out[eye] = Camera(position=tuple(pos), target=tuple(pos + 100 * fwd), up=tuple(up),
                          fov=float(np.degrees(fovy)))
    return out


def check_eyes(browser, scene, cameras, output_dir, tag) -> list:
    """Each eye's picture in the layer (display values over black) equals ``Image.to_uint8`` of the CPU's picture
    from that eye, both eyes shown with one exposure: the CPU's meter of the first eye's picture (+- 0.02 stops)."""
    shots = browser.evaluate("volumen.captureVR()")
    assert [s["shown"] for s in shots] == [shots[0]["shown"]] * 2, "the eyes are shown differently"
    shown = shots[0]["shown"]
    rows = []
    for i, s in enumerate(shots):
        x, y, w, h = s["viewport"]
        assert (w, h) == (EYE, EYE) and x == (0 if s["eye"] == "left" else EYE), s["viewport"]
        got = picture(s["rgba"], w, h)
        ref = render(scene, cameras[s["eye"]], (w, h), device="cpu")
        assert ref.alpha.max() > 0.2 and shown["tonemap"] == ref.display.tonemap
        if i == 0:
            assert abs(shown["exposure"] - ref.display.stops(ref.rgba)) <= EXPOSURE_TOL, (shown, ref.display)
        mean, p99, cover = compare(got[..., :3], displayed(ref, shown["exposure"]), rgb_only=True)
        rows.append((f"{tag} {s['eye']} ({shown['tonemap']} {shown['exposure']:+.3f})", mean, p99, cover))
        if mean > DISPLAY_MEAN_TOL / 2:
            save_pair(output_dir / f"web_xr_{tag}_{s['eye']}.png", got, displayed(ref, shown["exposure"]))
    print("\n".join(f"{n:40s} mean {m * 255:.2f}/255 p99 {p * 255:.2f}/255 coverage differs {c:.4f}"
                    for n, m, p, c in rows))
    assert len(rows) == 2 and all(m <= DISPLAY_MEAN_TOL and p <= DISPLAY_P99_TOL and c <= 0.005
                                  for _, m, p, c in rows), rows
    return rows


def test_headset_eyes_light_and_grab(xr_browser, head_server, output_dir):
    b = xr_browser
    vol = head_server.handlers.served().volume
    scene, cam, _ = reference_scenes.scenes()["head/composite/shadows-fast"]
    scene = scene.with_(volume=vol, display=Display())   # auto: tone mapped, exposure metered
    b.evaluate(f"volumen.show({{scene: {scene_json(scene)}, camera: {cam.to_json()}}})")
    assert b.evaluate("volumen.enterVR({governor: false})")
    dev = b.evaluate("({ipd: iwerDevice.ipd, fovy: iwerDevice.fovy})")
    # the head steps toward the volume and turns 12 degrees to the left
    head, head_q = HEAD0 + [0.02, -0.18, -0.27], _quat([0, 1, 0], 12)
    _set(b, "iwerDevice", head, head_q)
    b.evaluate("volumen.framesVR(2)")
    state = b.evaluate("volumen.stateVR()")
    model = _model(state)
    s = np.linalg.norm(model[:3, 0])
    assert np.isclose(s, 0.4 / vol.diagonal) and np.linalg.det(model[:3, :3]) > 0   # table-top, a rotation
    check_eyes(b, scene, eye_cameras(model, head, head_q, dev["ipd"], dev["fovy"]), output_dir, "shadows")

    # the right controller's trigger: pressed at one pose, dragged to another, released
    ctrl = "iwerDevice.controllers.right"
    _set(b, ctrl, HEAD0 + [0.15, -0.12, -0.4], _quat([1, 0, 0], -20))
    b.evaluate(f"{ctrl}.updateButtonValue('trigger', 1); volumen.framesVR(3)")
    where = HEAD0 + [0.12, -0.08, -0.42]
    aim = (model @ np.r_[vol.center, 1.0])[:3] - (where - HEAD0)   # toward the volume's centre
    aim /= np.linalg.norm(aim)
    q = _quat(np.cross([0, 0, -1], aim), np.degrees(np.arccos(-aim[2])))
    _set(b, ctrl, where, q)
    _button(b, ctrl, "trigger", 0, 3, 3)
    lights = [Light.from_dict(x) for x in b.evaluate("volumen.viewer.scene.lights")]
    inv = np.linalg.inv(model)
    pose = _pose(where - HEAD0, q)
    expected_pos = (inv @ np.r_[pose[:3, 3], 1.0])[:3]
    expected_dir = inv[:3, :3] @ -pose[:3, 2]
    assert len(lights) == len(scene.lights) + 1
    assert np.allclose(lights[-1].position, expected_pos, atol=1e-3)
    assert np.allclose(lights[-1].direction, expected_dir / np.linalg.norm(expected_dir), atol=1e-6)
    lit = scene.with_(lights=(*scene.lights, Light(position=tuple(expected_pos), direction=tuple(expected_dir),
                                                    exponent=10.0, kind="spot")))
    eyes = eye_cameras(model, head, head_q, dev["ipd"], dev["fovy"])
    check_eyes(b, lit, eyes, output_dir, "new-light")
    change = np.abs(render(lit, eyes["left"], (EYE, EYE)).rgba - render(scene, eyes["left"], (EYE, EYE)).rgba)
    assert change.max() > 0.1, "the new light changes nothing: the test would not see a misplaced one"

    # the left controller grabs the volume and turns 35 degrees about a tilted axis
    ctrl = "iwerDevice.controllers.left"
    p, q0 = HEAD0 + [-0.1, -0.2, -0.45], _quat([1, 0, 0], -30)
    _set(b, ctrl, p, q0)
    _button(b, ctrl, "squeeze", 1, 2, 3)
    turn = _quat([0.2, 1.0, 0.3], 35)
    q1 = np.r_[turn[3] * q0[:3] + q0[3] * turn[:3] + np.cross(turn[:3], q0[:3]), turn[3] * q0[3] - turn[:3] @ q0[:3]]
    _set(b, ctrl, p, q1)
    _button(b, ctrl, "squeeze", 0, 3, 2)
    after = _model(b.evaluate("volumen.stateVR()"))
    delta = after @ np.linalg.inv(model)
    angle = np.degrees(np.arccos(np.clip((np.trace(delta[:3, :3]) - 1) / 2, -1, 1)))
    print(f"grab: turned the controller 35 deg, the volume turned {angle:.4f} deg")
    assert abs(angle - 35.0) <= 1.0
    c = p - HEAD0
    expected = _pose(c, [0, 0, 0, 1]) @ _pose([0, 0, 0], turn) @ _pose(-c, [0, 0, 0, 1]) @ model
    assert np.allclose(after, expected, atol=1e-6)
    check_eyes(b, lit, eye_cameras(expected, head, head_q, dev["ipd"], dev["fovy"]), output_dir, "grabbed")


def test_headset_controls_and_governor(xr_browser, head_server):
    """A / X deletes the light nearest the controller; the thumbstick pushed right cycles to the next preset;
    both grips drawn apart scale the volume by the ratio of the hands' distances; the governor, fed slow frames,
    halves the samples per voxel twice and then the resolution, and gives them back on fast frames; frame
    times are reported."""
    b = xr_browser
    vol = head_server.handlers.served().volume
    scene, cam, _ = reference_scenes.scenes()["head/mip"]   # with the lights of the others; quick frames
    scene = scene.with_(volume=vol)
    b.evaluate(f"volumen.show({{scene: {scene_json(scene)}, camera: {cam.to_json()}}})")
    if not b.evaluate("volumen.xr.session !== null"):
        b.evaluate("volumen.enterVR({governor: false})")
    model = _model(b.evaluate("volumen.stateVR()"))
    inv = np.linalg.inv(model)
    # the right controller at the second light (its position in the room)
    near = (model @ np.r_[scene.lights[1].position, 1.0])[:3]
    ctrl = "iwerDevice.controllers.right"
    _set(b, ctrl, near + HEAD0, [0, 0, 0, 1])
    before = [np.linalg.norm((inv @ np.r_[near, 1.0])[:3] - lt.position) for lt in scene.lights]
    _button(b, ctrl, "a-button", 1, 1, 2)
    _button(b, ctrl, "a-button", 0, 0, 1)
    lights = [Light.from_dict(x) for x in b.evaluate("volumen.viewer.scene.lights")]
    assert int(np.argmin(before)) == 1 and lights == [scene.lights[0]]
    seen = []
    for push in (1, 1, -1):   # right, right, left: the next preset, the one after, back
        b.evaluate(f"{ctrl}.updateAxes('thumbstick', {push}, 0); volumen.framesVR(2)"
                   f".then(() => {ctrl}.updateAxes('thumbstick', 0, 0)).then(() => volumen.framesVR(2))")
        seen.append(b.evaluate("volumen.viewer.scene.transfer.name"))
    names = [n for n in b.evaluate("volumen.info.presets") if n != "mip-gray"]
    assert seen[1] == names[(names.index(seen[0]) + 1) % len(names)] and seen[2] == seen[0]

    left, right = "iwerDevice.controllers.left", "iwerDevice.controllers.right"
    _set(b, left, HEAD0 + [-0.1, -0.2, -0.4], [0, 0, 0, 1])
    _set(b, right, HEAD0 + [0.1, -0.2, -0.4], [0, 0, 0, 1])
    start = _model(b.evaluate("volumen.stateVR()"))
    b.evaluate(f"volumen.framesVR(1).then(() => {{ {left}.updateButtonValue('squeeze', 1); "
               f"{right}.updateButtonValue('squeeze', 1); }}).then(() => volumen.framesVR(2))")
    _set(b, left, HEAD0 + [-0.15, -0.2, -0.4], [0, 0, 0, 1])
    _set(b, right, HEAD0 + [0.15, -0.2, -0.4], [0, 0, 0, 1])
    b.evaluate(f"volumen.framesVR(2).then(() => {{ {left}.updateButtonValue('squeeze', 0); "
               f"{right}.updateButtonValue('squeeze', 0); }}).then(() => volumen.framesVR(1))")
    scaled = _model(b.evaluate("volumen.stateVR()"))
    assert np.isclose(np.linalg.norm(scaled[:3, 0]) / np.linalg.norm(start[:3, 0]), 1.5, rtol=1e-6)

    spv = b.evaluate("volumen.viewer.scene.sampling.samples_per_voxel")
    # the governor's steps fed 10 frames at a time (off for the real frames, which SwiftShader draws slowly)
    feed = "for (let i = 0; i < 10; i++) xr.record({ms}); xr.govern(); await volumen.viewer.idle();"
    levels = b.evaluate("(async () => { const xr = volumen.xr; xr.governor = false; xr.base = "
                        "volumen.viewer.scene.sampling.samples_per_voxel; const out = []; for (let k = 0; k < 4; k++) "
                        f"{{ {feed.format(ms=1000)} out.push(xr.stats()); }} return out; }})()")
    assert [(s["level"], s["scale"]) for s in levels] == [(1, 1), (2, 1), (3, 0.75), (4, 0.5)]
    assert [s["samples_per_voxel"] for s in levels] == [spv / 2, spv / 4, spv / 4, spv / 4]
    stats = b.evaluate("volumen.framesVR(2).then(() => volumen.stateVR().stats)")
    assert stats["frames"] >= 1 and stats["mean_ms"] > 0
    back = b.evaluate(f"(async () => {{ const xr = volumen.xr; for (let k = 0; k < 4; k++) "
                      f"{{ {feed.format(ms=0.01)} }} return xr.stats(); }})()")
    assert back["level"] == 0 and back["samples_per_voxel"] == spv
