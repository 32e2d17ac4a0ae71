"""The vessel profile under the page's slice views (``volumen serve --report``), in headless Chromium: the plotted
curve is report.json's equivalent diameter against the arc, a click on the plot moves the crosshair to that
section's centerline point, and the numbers shown are report.json's. The profile is the stenosis phantom's
(:func:`volumen.analysis.profile` with its true lumen), written by :func:`volumen.analysis.write_report`."""

from __future__ import annotations

import json
import re
import subprocess
import sys

import numpy as np
import pytest
from web_helpers import start_server


@pytest.fixture(scope="module")
def stenosis_report(tmp_path_factory):
    from volumen.analysis import profile, write_report
    from volumen.data import phantom

    vol = phantom("stenosis")
    lm, tube = vol.meta["truth"]["landmarks"], vol.meta["truth"]["vessel"]
    folder = tmp_path_factory.mktemp("report")
    write_report(profile(vol, lm["start"], lm["end"], lumen=tube.mask), folder)
    return vol, folder


@pytest.fixture(scope="module")
def page(chromium, stenosis_report):
    from volumen.core import Scene, default_camera
    from volumen.web import Chromium
    from volumen.web._profile_route import read_profile

    vol, folder = stenosis_report
    srv = start_server(vol, Scene(volume=vol), default_camera(vol))
    srv.handlers.profile = read_profile(folder, vol)
    with Chromium((1000, 800)) as b:
        b.open(srv.url)
        b.evaluate("volumen.shown()")
        yield b, srv, json.loads((folder / "report.json").read_text())["table"]
    srv.stop()


def _points(text: str) -> np.ndarray:
    return np.array([[float(v) for v in p.split(",")] for p in text.split()])


def test_the_plotted_curve_is_the_reports_diameter(page):
    browser, _, table = page
    got = browser.evaluate("""(() => { const p = volumen.profile, a = p.axes;
      return {line: p.svg.querySelector('polyline.diameter').getAttribute('points'), axes: a,
              box: p.svg.getBoundingClientRect().toJSON(), view: p.svg.getAttribute('viewBox')}; })()""")
    line, a = _points(got["line"]), got["axes"]
    assert got["view"].split()[2:] == [f"{got['box']['width']:g}", f"{got['box']['height']:g}"]  # user units: px
    arc, d = np.array(table["arc_mm"]), np.array(table["diameter_mm"])
    x = a["left"] + (arc - arc[0]) / (arc[-1] - arc[0]) * a["width"]
    y = a["top"] + (a["mm"][1] - d) / (a["mm"][1] - a["mm"][0]) * a["height"]
    assert a["arc"] == [arc[0], arc[-1]] and a["mm"][0] == 0 and a["mm"][1] >= max(table["max_diameter_mm"])
    assert line.shape == (len(arc), 2)
    assert np.abs(line - np.stack([x, y], axis=1)).max() < 1.0   # px
    marks = browser.evaluate("[...volumen.profile.svg.querySelectorAll('line.mark')].map((l) => "
                             "[l.dataset.mark, +l.getAttribute('x1')])")
    report = {k: json.loads(json.dumps(v)) for k, v in page[1].handlers.profile.items() if k in ("stenosis", "maximum")}
    for name, x1 in marks:
        want = a["left"] + (report[name]["arc_mm"] - arc[0]) / (arc[-1] - arc[0]) * a["width"]
        assert abs(x1 - want) < 1.0, name


def test_a_click_moves_the_crosshair_to_the_section_and_shows_its_numbers(page):
    browser, srv, table = page
    arc = np.array(table["arc_mm"])
    k = int(np.argmin(table["diameter_mm"]))  # the stenosis's narrowest section
    a = browser.evaluate("volumen.profile.axes")
    box = browser.evaluate("volumen.profile.svg.getBoundingClientRect().toJSON()")
    x = box["left"] + a["left"] + (arc[k] - arc[0]) / (arc[-1] - arc[0]) * a["width"]
    y = box["top"] + a["top"] + 0.5 * a["height"]
    browser.mouse("pressed", x, y, "left")
    browser.mouse("released", x, y, "left")
    browser.evaluate("volumen.measures.slices.latest")
    point = np.array([table[c][k] for c in ("x_mm", "y_mm", "z_mm")])
    assert np.allclose(browser.evaluate("volumen.measures.slices.crosshair"), point, atol=1e-9)
    vol = srv.handlers.served().volume
    v = browser.evaluate("volumen.measures.slices.views.axial")  # the slice's crossing is the section's voxel
    m = np.array(v["map"])
    shown = m[0] + v["cross"]["col"] * m[1] + v["cross"]["row"] * m[2]
    assert np.abs((shown - point)[:2]).max() <= max(vol.spacing)
    text = browser.evaluate("volumen.profile.numbers.textContent")
    numbers = [float(n) for n in re.findall(r"\d+\.\d", text)]
    assert numbers == [round(table[c][k], 1) for c in ("arc_mm", "area_mm2", "diameter_mm", "min_diameter_mm",
                                                        "max_diameter_mm", "inscribed_radius_mm")]


def test_serve_refuses_a_profile_whose_centerline_leaves_the_scan_in_one_line(stenosis_report, tmp_path):
    _, folder = stenosis_report
    report = json.loads((folder / "report.json").read_text())
    report["table"]["x_mm"] = [x + 1000.0 for x in report["table"]["x_mm"]]  # a metre off: another scan's
    moved = tmp_path / "report.json"
    moved.write_text(json.dumps(report))
    for args in (["--profile", str(moved)], ["--profile", str(tmp_path / "none.json")]):
        r = subprocess.run([sys.executable, "-m", "volumen", "serve", "phantom:stenosis", *args, "--no-browser",
                            "--port", "0"], capture_output=True, text=True, timeout=60)
        assert r.returncode == 1 and r.stdout == "", args
        assert len(r.stderr.strip().splitlines()) == 1 and "profile" in r.stderr, args
