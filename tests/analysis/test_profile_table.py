"""The profile as a table: CSV, JSON and the notebook's view carry the same numbers as the object."""

from __future__ import annotations

import json

import numpy as np


def test_csv_holds_the_table(profiles, tmp_path):
    p = profiles["grown"]
    path = tmp_path / "profile.csv"
    p.to_csv(path)
    lines = path.read_text(encoding="utf-8").splitlines()
    header = lines[0].split(",")
    assert header == list(p.columns()) and len(lines) == len(p.sections.area) + 1
    table = np.array([[float(v) for v in ln.split(",")] for ln in lines[1:]])
    assert np.allclose(table[:, header.index("diameter_mm")], p.sections.diameter, atol=0.005)
    assert np.allclose(table[:, header.index("arc_mm")], p.centerline.arc, atol=0.005)


def test_json_report_round_trips(profiles):
    p = profiles["grown"]
    doc = json.loads(json.dumps(p.to_dict()))
    summary = doc["summary"]
    assert summary["length_mm"] == round(p.length, 1) and summary["sections"] == len(p.sections.area)
    assert summary["stenosis"]["percent"] == round(p.stenosis.percent, 1)
    assert summary["maximum"]["diameter_mm"] == round(p.maximum.diameter, 1)
    assert np.allclose(doc["table"]["area_mm2"], p.sections.area, atol=0.005)


def test_the_notebook_shows_a_summary_and_the_plot(profiles):
    html = profiles["grown"]._repr_html_()
    assert "<table>" in html and "stenosis" in html and "data:image/png;base64," in html
