"""The desktop page in headless Chromium (WebGL2 on SwiftShader) against ``volumen.render(device="cpu")``:
every mode and every shading model but path tracing, on the head phantom and on VMTK's aorta (resampled by
the server to a 1 MiB texture budget, as a headset's would be), plus crop box, clip plane, orthographic and
pre-integrated variants; the mouse gestures move the camera and the lights exactly as
``volumen.core.gestures`` does, at reduced resolution while dragging; the cones are drawn."""

from __future__ import annotations

import dataclasses
import time

import numpy as np
import pytest

from tests.web.web_helpers import (
    DISPLAY_MEAN_TOL,
    DISPLAY_P99_TOL,
    EXPOSURE_TOL,
    MEAN_TOL,
    P99_TOL,
    capture,
    compare,
    displayed,
    reference_scenes,
    save_pair,
    show,
)
from volumen.core import Camera, Clipping, ClipPlane, Display, Light, gestures
from volumen.render import render

SIZE = (64, 64)


@pytest.fixture(scope="module")
def browser(chromium):
    from volumen.web import Chromium

    with Chromium((400, 300)) as b:
        yield b


def _extra(data, vol):
    """Variants beyond the reference scenes: a crop box and a clip plane, orthographic, pre-integrated."""
    scenes = reference_scenes.scenes()
    scene, cam, _ = scenes[f"{data}/composite/shadows-fast"]
    nz, ny, nx = vol.shape
    clip = Clipping(crop=(0.1 * nx, 0.85 * nx, 0.0, 0.9 * ny, 0.15 * nz, nz - 1.0),
                    planes=(ClipPlane(point=tuple(np.asarray(vol.center)), normal=(0.3, -1.0, 0.2)),))
    yield f"{data}/composite/shadows-fast+crop+plane", scene.with_(clipping=clip), cam
    scene, cam, _ = scenes[f"{data}/isosurface/phong"]
    yield f"{data}/isosurface/phong ortho", scene, dataclasses.replace(cam, projection="orthographic")
    scene, cam, _ = scenes[f"{data}/composite/headlight"]
    yield f"{data}/composite/headlight preintegrated", scene.with_(
        sampling=dataclasses.replace(scene.sampling, preintegrate=True)), cam


@pytest.mark.parametrize("data", ["head", "aorta"])
def test_page_equals_cpu_every_mode_and_shading(data, browser, request, output_dir):
    """mip, minip, average; composite and isosurface x none, headlight, phong, shadows (illumination volumes
    and shadow rays), scattering (tests/render/reference_scenes.py: two lights, jitter on): the page's linear
    picture (before the display transform) equals the CPU's picture of the served volume, mean |RGBA diff| <=
    0.01 and p99 <= 0.05, and both pictures show something on the same pixels; what the page shows (the canvas,
    through the display transform: the ACES curve, sRGB and metered exposure for the lit models, linear for the
    others) equals ``Image.to_uint8`` of the CPU's picture, mean |RGB diff| <= 2/255 and p99 <= 8/255, with the
    same curve and the same metered exposure (+- 0.02 stops)."""
    server = request.getfixturevalue(f"{data}_server")
    browser.open(server.url)
    vol = server.handlers.served().volume
    cases = [(name, sc, cam) for name, (sc, cam, _) in reference_scenes.scenes().items()
             if name.startswith(data + "/") and "pathtrace" not in name]
    if data == "head":
        cases += list(_extra(data, vol))
    rows = []
    for name, scene, cam in cases:
        scene = scene.with_(volume=vol, display=Display())   # auto: the lit models tone mapped, the others linear
        t0 = time.perf_counter()
        got = show(browser, scene, cam, SIZE, linear=True)
        t1 = time.perf_counter()
        ref = render(scene, Camera.from_dict(got["camera"]), SIZE, device="cpu")
        print(f"{name} page {t1 - t0:.2f} s, cpu {time.perf_counter() - t1:.2f} s")
        assert ref.alpha.max() > 0.2, name
        mean, p99, cover = compare(got["linear"], ref.rgba)
        shown, cpu_ev = got["shown"], ref.display.stops(ref.rgba)
        dmean, dp99, _ = compare(got["rgba"][..., :3], displayed(ref), rgb_only=True)
        rows.append((name, mean, p99, cover, shown["tonemap"], shown["exposure"] - cpu_ev, dmean, dp99))
        assert shown["tonemap"] == ref.display.tonemap, (name, shown, ref.display)
        if mean > MEAN_TOL / 2 or dmean > DISPLAY_MEAN_TOL / 2:
            save_pair(output_dir / f"web_{name.replace('/', '_').replace(' ', '_')}.png", got["rgba"], displayed(ref))
    print(f"\n{data}: served volume {vol.shape[::-1]} (x, y, z), {SIZE[0]}x{SIZE[1]} px; linear RGBA, then shown RGB")
    print("\n".join(f"{r[0]:48s} mean {r[1]:.5f} p99 {r[2]:.4f} coverage differs {r[3]:.4f} | {r[4]:6s} "
                    f"exposure {r[5]:+.4f} stops, mean {r[6] * 255:.2f}/255 p99 {r[7] * 255:.2f}/255" for r in rows))
    bad = [r for r in rows if not (r[1] <= MEAN_TOL and r[2] <= P99_TOL and r[3] <= 0.005 and abs(r[5]) <= EXPOSURE_TOL
                                   and r[6] <= DISPLAY_MEAN_TOL and r[7] <= DISPLAY_P99_TOL)]
    assert len(rows) == (18 if data == "head" else 15) and not bad, bad
    assert {r[4] for r in rows} == {"aces", "linear"}


def _canvas_origin(browser) -> tuple[float, float]:
    r = browser.evaluate("(() => { const b = document.getElementById('gl').getBoundingClientRect(); "
                         "return [b.left, b.top]; })()")
    return r[0], r[1]


def _drag(browser, start, steps, button="left", modifiers=0, during=None):
    """Press at ``start`` (page px), move by each (dx, dy) of ``steps``, call ``during()``, release."""
    x, y = start
    browser.mouse("pressed", x, y, button, modifiers)
    for dx, dy in steps:
        x, y = x + dx, y + dy
        browser.mouse("moved", x, y, button, modifiers)
        browser.evaluate("new Promise((r) => requestAnimationFrame(r))")   # one pointermove per frame
    seen = during() if during else None
    browser.mouse("released", x, y, button, modifiers)
    return seen


def test_gestures_move_the_camera_and_lights_as_the_application_does(browser, head_server):
    """Left drag orbits, shift + left drag pans, right drag zooms, a drag on a light's cone moves the light,
    ctrl + drag aims it: the page's camera and lights equal ``volumen.core.gestures`` applied to the same pixel
    offsets (to 1e-6 mm); while the button is down the picture is drawn at half resolution, after it at full;
    the final picture equals the CPU's (linear, and as shown: the picture is past 128 x 128 pixels, so the page
    meters its exposure on a subsample of it: within 0.05 stops of the CPU's meter of every pixel); the cone of
    a light is drawn over the picture."""
    browser.open(head_server.url)
    scene, cam, _ = reference_scenes.scenes()["head/composite/phong"]
    vol = head_server.handlers.served().volume
    r, u, f = cam.basis()
    inside = Light(position=tuple(np.asarray(vol.center) + vol.diagonal * (0.25 * r + 0.15 * u - 0.4 * f)),
                   direction=tuple(f - 0.3 * r), exponent=4.0, intensity=0.8)
    scene = scene.with_(volume=vol, lights=(inside, scene.lights[1]), display=Display())
    size = (160, 120)
    show(browser, scene, cam, size)
    ox, oy = _canvas_origin(browser)
    centre = (ox + 60, oy + 50)
    steps = [(6, 2), (10, -3), (4, 5)]
    scale_during = _drag(browser, centre, steps, during=lambda: browser.evaluate(
        "new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(() => "
        "r(volumen.viewer.lastDraw.scale))))"))
    expected = cam
    for dx, dy in steps:
        expected = gestures.orbit(expected, dx, dy)
    _drag(browser, centre, [(-7, 3)], modifiers=8)   # shift
    expected = gestures.pan(expected, -7, 3, size)
    _drag(browser, centre, [(0, -12)], button="right")
    expected = gestures.drag_zoom(expected, -12)
    browser.evaluate("volumen.viewer.settled()")
    got = capture(browser, linear=True)
    page = Camera.from_dict(got["camera"])
    for field in ("position", "target", "up"):
        assert np.allclose(getattr(page, field), getattr(expected, field), atol=1e-6), field
    assert scale_during == 0.5 and browser.evaluate("volumen.viewer.lastDraw.scale") == 1
    ref = render(scene, page, size, device="cpu")
    mean, p99, _ = compare(got["linear"], ref.rgba)
    assert mean <= MEAN_TOL and p99 <= P99_TOL
    ev, cpu_ev = got["shown"]["exposure"], ref.display.stops(ref.rgba)
    dmean, dp99, _ = compare(got["rgba"][..., :3], displayed(ref, ev), rgb_only=True)
    print(f"gestures: exposure metered on a subsample {ev:+.4f}, on every pixel (cpu) {cpu_ev:+.4f} stops; shown "
          f"mean {dmean * 255:.2f}/255 p99 {dp99 * 255:.2f}/255")
    assert got["shown"]["tonemap"] == "aces" and abs(ev - cpu_ev) <= 0.05
    assert dmean <= DISPLAY_MEAN_TOL and dp99 <= DISPLAY_P99_TOL

    # a light of the scene: drag its cone's apex, then ctrl + drag to aim it
    light = scene.lights[0]
    colrow, depth = page.project(np.asarray(light.position)[None], size)
    col, row = (float(v) for v in colrow[0])
    assert 5 < col < size[0] - 5 and 5 < row < size[1] - 5 and depth[0] > 0, "the light is not in the picture"
    overlay = browser.evaluate(f"(() => {{ const c = document.getElementById('overlay'); const d = c.getContext('2d')"
                               f".getImageData({int(col) - 3}, {int(row) - 3}, 7, 7).data; "
                               f"return Math.max(...Array.from(d).filter((_, i) => i % 4 === 3)); }})()")
    assert overlay > 100, "no cone drawn at the light"
    _drag(browser, (ox + col, oy + row), [(5, -4)])
    moved = gestures.move_light(light, page, 5, -4, size)
    colrow, _ = page.project(np.asarray(moved.position)[None], size)
    _drag(browser, (ox + float(colrow[0, 0]), oy + float(colrow[0, 1])), [(8, 2)], modifiers=2)   # ctrl
    aimed = gestures.aim_light(moved, page, 8, 2)
    browser.evaluate("volumen.viewer.settled()")
    lights = [Light.from_dict(x) for x in browser.evaluate("volumen.viewer.scene.lights")]
    assert np.allclose(lights[0].position, aimed.position, atol=1e-6)
    assert np.allclose(np.asarray(lights[0].direction) / np.linalg.norm(lights[0].direction),
                       np.asarray(aimed.direction) / np.linalg.norm(aimed.direction), atol=1e-9)
    assert lights[1] == scene.lights[1]
