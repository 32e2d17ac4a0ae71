"""The page as a user first sees it, in a 1280 x 800 window of headless Chromium: the status line sits below the
views (its box meets none of the 3-D view's, the slice panels' or the side panel's), and the 3-D view frames the
subject as ``volumen render`` does (the camera ``volumen serve`` sends is ``core.default_camera``'s, and the
subject spans at least half of the view's shorter side, measured on the canvas as
``tests/cli/test_default_pictures.py`` measures a PNG); each notice of the panel is listed once."""

from __future__ import annotations

import numpy as np
import pytest

from tests.web.web_helpers import capture, start_server
from volumen.cli import build_parser
from volumen.cli._serve import _scene_and_camera
from volumen.core import Camera, default_camera
from volumen.data import phantom

WINDOW = (1280, 800)
#: the subject: canvas pixels of display luminance (Rec. 709) above this (the view's background is black)
SUBJECT_LUMINANCE = 0.04
FILL_BAR = 0.5
BOXES = ("#view3d", "#slices figure:nth-child(1)", "#slices figure:nth-child(2)", "#slices figure:nth-child(3)",
         "#panel")


@pytest.fixture(scope="module")
def browser(chromium):
    from volumen.web import Chromium

    with Chromium(WINDOW) as b:
        b.set_size(*WINDOW)
        yield b


def _rect(browser, selector: str) -> tuple[float, float, float, float]:
    r = browser.evaluate(f"(() => {{ const r = document.querySelector('{selector}').getBoundingClientRect(); "
                         "return [r.left, r.top, r.right, r.bottom]; })()")
    return tuple(float(v) for v in r)


def _overlap(a, b) -> float:
    """Area (CSS px^2) shared by the boxes ``a`` and ``b`` (left, top, right, bottom)."""
    return max(0.0, min(a[2], b[2]) - max(a[0], b[0])) * max(0.0, min(a[3], b[3]) - max(a[1], b[1]))


@pytest.mark.parametrize("name", ["head", "mr_head"])
def test_the_status_line_is_clear_of_the_views_and_the_view_frames_the_subject(browser, name):
    vol = phantom(name, size=64)
    scene, camera = _scene_and_camera(build_parser().parse_args(["serve", f"phantom:{name}?size=64"]), vol)
    server = start_server(vol, scene, camera)
    try:
        browser.open(server.url)
        browser.evaluate("volumen.shown()")
        status = _rect(browser, "#status")
        assert status[3] > status[1] and status[2] > status[0], "the status line is not shown"
        for sel in BOXES:
            assert _overlap(status, _rect(browser, sel)) == 0.0, f"the status line overlaps {sel}"
        got = capture(browser)
    finally:
        server.stop()
    page = Camera.from_dict(got["camera"])
    expected = default_camera(vol)
    for field in ("position", "target", "up"):
        assert np.allclose(getattr(page, field), getattr(expected, field), atol=1e-6), field
    lum = got["rgba"][..., :3] @ np.array([0.2126, 0.7152, 0.0722])
    rows, cols = np.nonzero(lum > SUBJECT_LUMINANCE)
    fill = max(np.ptp(rows) + 1, np.ptp(cols) + 1) / min(lum.shape)
    print(f"{name}: the subject spans {fill:.2f} of the 3-D view's shorter side ({lum.shape[1]} x {lum.shape[0]})")
    assert fill >= FILL_BAR


def test_each_notice_is_listed_once(browser):
    """A float MRI is sent as half floats, which the page notes: once, also where the volume was packed before the
    page asked for info.json (both answers then carry the notice)."""
    vol = phantom("mr_head", size=48, dtype="float32")
    scene, camera = _scene_and_camera(build_parser().parse_args(["serve", "phantom:mr_head?size=48"]), vol)
    server = start_server(vol, scene, camera)
    try:
        assert not server.handlers.served().encoded[2], "the MRI is sent exactly: no notice to repeat"
        browser.open(server.url)
        browser.evaluate("volumen.shown()")
        notes = browser.evaluate("[...document.querySelectorAll('#panel .notices li')].map((li) => li.textContent)")
    finally:
        server.stop()
    assert len(notes) == len(set(notes)) >= 1, notes
