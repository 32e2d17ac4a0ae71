"""The page opens measurements made elsewhere (headless Chromium): a DICOM SR the user opens is read by the server
(``open-measurements.json``) and shown on the slice views; an SR of another study is refused in one line that
names neither file nor scan and nothing shown is lost; ``volumen serve --measurements`` gives the page its
measurements at start, and refuses another study's SR in one line, exit 1."""

from __future__ import annotations

import base64

import numpy as np
import pytest

import volumen
from tests.io.dicom_factory import new_uid, stack_positions, write_series
from tests.web.web_helpers import reference_scenes, start_server
from volumen import measure
from volumen.cli import main


def _write_ct(folder, study_uid: str):
    """A small axial CT series (7 slices of 48 x 48, 1 mm pixels, 2 mm apart) of study ``study_uid``."""
    raw = np.random.default_rng(3).normal(40, 30, (7, 48, 48)).astype(np.int16)
    pos = stack_positions((-24.0, -24.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), np.arange(7) * 2.0)
    write_series(folder, raw, row_dir=(1.0, 0.0, 0.0), col_dir=(0.0, 1.0, 0.0), positions=pos, pixel_spacing=(1, 1),
                 patient={"PatientName": "Anonymous^", "PatientID": "0", "StudyInstanceUID": study_uid},
                 series_uid=new_uid(f"page-sr-{folder}"))
    return volumen.load(folder)


def _report(vol, path):
    """An SR of a ruler, an angle, a point and an ellipse region on ``vol``, saved at ``path``."""
    c = vol.center
    items = measure.Measurements([
        measure.distance(c - (10, 0, 0), c + (12, 0, 0), volume=vol, label="ruler"),
        measure.angle(c + (8, 0, 0), c, c + (0, 8, 0), volume=vol),
        measure.point(c + (2, 3, 0), volume=vol),
        measure.roi_stats(vol, measure.slice_plane(vol, "axial", 3), measure.Ellipse((20.0, 20.0), (6.0, 4.0))),
    ])
    measure.make_sr(items, vol).save_as(path)
    return items


@pytest.fixture(scope="module")
def cts(tmp_path_factory):
    root = tmp_path_factory.mktemp("page-sr")
    ct, other = _write_ct(root / "ct", new_uid("study-a")), _write_ct(root / "other", new_uid("study-b"))
    items = _report(ct, root / "ct.dcm")
    _report(other, root / "other.dcm")
    return ct, items, root


@pytest.fixture(scope="module")
def ct_server(cts):
    scene, cam, _ = reference_scenes.scenes()["head/composite/headlight"]
    srv = start_server(cts[0], scene, cam)
    yield srv
    srv.stop()


@pytest.fixture(scope="module")
def browser(chromium):
    from volumen.web import Chromium

    with Chromium((900, 700)) as b:
        yield b


def _open(browser, path) -> int:
    """Open the file at ``path`` on the page as the user would (its bytes to the page's opener)."""
    data = base64.b64encode(path.read_bytes()).decode()
    return browser.evaluate(f"volumen.measures.open(new Blob([Uint8Array.from(atob('{data}'), "
                            "(c) => c.charCodeAt(0))]))")


def test_an_sr_opened_on_the_page_shows_its_measurements(browser, ct_server, cts):
    ct, items, root = cts
    browser.open(ct_server.url)
    browser.evaluate("volumen.shown()")
    assert _open(browser, root / "ct.dcm") == 4
    shown = measure.Measurements.from_dicts(browser.evaluate("volumen.measurements()")["measurements"])
    for got, made in zip(shown, items, strict=True):
        assert got.kind == made.kind
        assert np.allclose(got.points, made.points, atol=1e-3)  # an SR keeps 32-bit floats
    assert abs(shown[1].degrees - 90.0) < 0.5 and abs(shown[0].mm - 22.0) < 1e-3
    texts = browser.evaluate("[...document.querySelectorAll('svg.measures[data-plane=axial] text')]"
                             ".map((t) => t.textContent)")
    assert "22.0 mm" in texts and "90.0\u00b0" in texts

    assert _open(browser, root / "other.dcm") == 0  # another study: refused, nothing shown is lost
    note = browser.evaluate("document.querySelector('.measure-note').textContent")
    assert note == "the SR is of another study than the scan shown"
    assert len(browser.evaluate("volumen.measurements()")["measurements"]) == 4
    (root / "junk.bin").write_bytes(b"not a report" * 20)
    assert _open(browser, root / "junk.bin") == 0  # neither an SR nor JSON: one line, nothing lost
    note = browser.evaluate("document.querySelector('.measure-note').textContent")
    assert note.startswith("the file holds no measurements volumen reads") and "\n" not in note
    assert len(browser.evaluate("volumen.measurements()")["measurements"]) == 4


def test_serve_opens_the_page_with_an_srs_measurements(browser, ct_server, cts, capsys):
    ct, _, root = cts
    ct_server.handlers.opening = measure.load_measurements(root / "ct.dcm", volume=ct).to_dicts()
    try:
        browser.open(ct_server.url)
        browser.evaluate("volumen.shown()")
        assert len(browser.evaluate("volumen.measurements()")["measurements"]) == 4
    finally:
        ct_server.handlers.opening = []
    out = root / "never.png"
    assert main(["serve", str(root / "ct"), "--measurements", str(root / "other.dcm"), "--screenshot", str(out)]) == 1
    err = capsys.readouterr().err.strip()
    assert "not of the scan's study" in err and "\n" not in err and not out.exists()
