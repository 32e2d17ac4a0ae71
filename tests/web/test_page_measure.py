"""Rulers and regions on the page's slice views (headless Chromium), placed, moved and deleted by simulated mouse
input: the value drawn beside each follows the drag, every view that cuts it shows it, a region's statistics are
the scan's voxels' (``volumen.measure.roi_stats``), and the page's measurements read back as volumen.measure's."""

from __future__ import annotations

import json
import time

import numpy as np
import pytest

from volumen import measure


@pytest.fixture(scope="module")
def browser(chromium):
    from volumen.web import Chromium

    with Chromium((900, 700)) as b:
        yield b


def _frame(browser):
    browser.evaluate("new Promise((r) => requestAnimationFrame(r))")


def _view(browser, plane: str) -> dict:
    """The axial picture's box on the page, its scale (CSS px per picture pixel), its map and crossing."""
    return browser.evaluate(f"""(() => {{
      const v = volumen.measures.slices.views.{plane}, b = v.img.getBoundingClientRect();
      const s = Math.min(b.width / v.img.naturalWidth, b.height / v.img.naturalHeight);
      return {{left: b.left + (b.width - s * v.img.naturalWidth) / 2,
               top: b.top + (b.height - s * v.img.naturalHeight) / 2, s, map: v.map, cross: v.cross}}; }})()""")


def _captions(browser, plane: str) -> list[str]:
    return browser.evaluate(f"[...document.querySelectorAll('svg.measures[data-plane={plane}] text')]"
                            ".map((t) => t.textContent)")


def _drag(browser, a, b, steps=4, button="left"):
    browser.mouse("pressed", *a, button)
    seen = []
    for t in np.linspace(0, 1, steps + 1)[1:]:
        browser.mouse("moved", *(np.add(a, t * np.subtract(b, a))), button)
        _frame(browser)
        seen.append(_captions(browser, "axial"))
    browser.mouse("released", *b, button)
    _frame(browser)
    return seen


def _tool(browser, tool: str | None) -> None:
    """Click the tool's button (None: the crosshair's)."""
    browser.evaluate(f"document.querySelector('.measure-tools button[data-tool=\"{tool or ''}\"]').click()")


def test_a_ruler_placed_moved_and_deleted_with_the_mouse(browser, head_server):
    browser.open(head_server.url)
    browser.evaluate("volumen.shown()")
    _tool(browser, "ruler")
    v = _view(browser, "axial")
    mm_per_px = np.linalg.norm(v["map"][1]) / v["s"]
    y = v["top"] + (v["cross"]["row"] + 0.5) * v["s"]  # the row the coronal plane cuts
    x = v["left"] + (v["cross"]["col"] + 0.5) * v["s"]  # and the column of the sagittal plane
    a, b = (x - 60, y), (x + 40, y)
    seen = _drag(browser, a, b)
    (ruler,) = browser.evaluate("volumen.measurements()")["measurements"]
    got = measure.from_dict(ruler)
    voxel = min(head_server.handlers.served().volume.spacing)
    assert abs(got.mm - 100 * mm_per_px) < 0.5 * voxel
    lengths = [float(c[0].split()[0]) for c in seen]
    assert lengths == sorted(lengths) and lengths[0] < lengths[-1]  # the value followed the drag
    assert _captions(browser, "axial") == [f"{got.mm:.1f} mm"]
    for plane in ("coronal", "sagittal"):  # the coronal slice holds it, the sagittal one is crossed by it
        assert _captions(browser, plane) == [f"{got.mm:.1f} mm"], plane
    centre = browser.evaluate("volumen.measures.slices.crosshair")

    _tool(browser, None)  # an end is grabbed in any mode, and the drag leaves the crosshair
    _drag(browser, b, (b[0] + 20, b[1]))
    (moved,) = browser.evaluate("volumen.measurements()")["measurements"]
    assert abs(measure.from_dict(moved).mm - 120 * mm_per_px) < 0.5 * voxel
    assert browser.evaluate("volumen.measures.slices.crosshair") == centre
    browser.mouse("pressed", b[0] + 20, b[1], "right")
    browser.mouse("released", b[0] + 20, b[1], "right")
    assert browser.evaluate("volumen.measurements()")["measurements"] == []


def test_a_region_shows_the_statistics_of_the_scans_voxels(browser, head_server):
    browser.open(head_server.url)
    browser.evaluate("volumen.shown()")
    _tool(browser, "ellipse")
    v = _view(browser, "axial")
    x = v["left"] + (v["cross"]["col"] + 0.5) * v["s"]
    y = v["top"] + (v["cross"]["row"] + 0.5) * v["s"]
    _drag(browser, (x - 30, y - 20), (x + 20, y + 25))
    end = time.monotonic() + 30
    while not _captions(browser, "axial")[0].startswith("mean") and time.monotonic() < end:
        time.sleep(0.05)
    (d,) = browser.evaluate("volumen.measurements()")["measurements"]
    region = measure.from_dict(d)
    truth = measure.roi_stats(head_server.handlers.source, region.plane, region.shape)
    assert region.voxels == truth.voxels > 20
    assert region.mean == pytest.approx(truth.mean, rel=0.005) and region.sd == pytest.approx(truth.sd, rel=0.005)
    assert _captions(browser, "axial")[0].startswith(f"mean {round(truth.mean)} ")

    state = browser.evaluate("volumen.measurements()")  # the page's state survives a reload
    browser.open(head_server.url)
    browser.evaluate("volumen.shown()")
    assert browser.evaluate(f"volumen.loadMeasurements({json.dumps(state)})") == 1
    (back,) = browser.evaluate("volumen.measurements()")["measurements"]
    (was,) = state["measurements"]
    assert {k: v for k, v in back.items() if k != "shape"} == {k: v for k, v in was.items() if k != "shape"}
    assert np.allclose(back["shape"]["center"] + back["shape"]["radii"], was["shape"]["center"] + was["shape"]["radii"],
                       rtol=0, atol=1e-9)  # through world points and back: the last bits of a mm
    assert _captions(browser, "axial")[0].startswith(f"mean {round(truth.mean)} ")


def test_a_3d_ruler_picks_the_points_the_cpu_picks(browser, head_server):
    """Two clicks on the page's 3-D picture with the 3-D ruler on: each end is the CPU's pick
    (``volumen.measure.pick``, on the served volume) of the clicked pixel for the page's scene and camera, within
    a voxel; the ruler is drawn over the picture with its length, and on the slice views that cut it."""
    from volumen.core import Camera, Scene

    browser.open(head_server.url)
    browser.evaluate("volumen.shown()")
    browser.evaluate("document.querySelector('#view3d button.ruler3d').click()")
    box = browser.evaluate("(() => { const c = document.getElementById('gl'), b = c.getBoundingClientRect(); "
                           "return [b.left, b.top, b.width, b.height, c.width, c.height]; })()")
    left, top, width, height, w, h = box
    clicks = [(0.42, 0.45), (0.6, 0.55)]
    for fx, fy in clicks:
        browser.mouse("pressed", left + fx * width, top + fy * height)
        browser.mouse("released", left + fx * width, top + fy * height)
        browser.evaluate("volumen.ruler3d.picking")
    (d,) = browser.evaluate("volumen.measurements()")["measurements"]
    state = browser.evaluate("({scene: volumen.viewer.scene, camera: volumen.viewer.camera})")
    served = head_server.handlers.served().volume
    scene = Scene.from_dict({**state["scene"], "volume": ""}, volume=served)
    camera = Camera.from_dict(state["camera"])
    for (fx, fy), end in zip(clicks, (d["start"], d["end"]), strict=True):
        x, y = np.floor(fx * width * w / width) + 0.5, np.floor(fy * height * h / height) + 0.5
        cpu = measure.pick(scene, camera, (w, h), x, y)
        assert np.linalg.norm(np.subtract(end, cpu)) < max(served.spacing), (fx, fy)
    ruler = measure.from_dict(d)
    assert ruler.mm > 10
    drawn = browser.evaluate("[...document.querySelectorAll('#view3d .ruler3d-layer text')].map((t) => t.textContent)")
    assert drawn == [f"{ruler.mm:.1f} mm"]
