"""Cross-sections along a diseased artery against the stenosis phantom's analytic geometry: equivalent diameter
along the whole path, the stenosis, the maximum diameter, the path length, the tortuosity and the inscribed
spheres, from the landmarks alone (the lumen grown from the data, its contrast fading along it and layered
across it) and from the true lumen mask."""

from __future__ import annotations

import numpy as np
import pytest

from tests.analysis.analysis_helpers import on_truth

SOURCES = ["grown", "mask"]


@pytest.mark.parametrize("source", SOURCES)
def test_equivalent_diameter_within_a_third_of_a_voxel_along_the_whole_path(stenosis, truth_line, profiles, source):
    """|d_eq - 2 r_section| <= 0.3 voxel at every section, r_section the analytic section's equivalent radius."""
    p = profiles[source]
    arc = on_truth(truth_line, p.centerline.points)
    analytic = 2.0 * np.interp(arc, truth_line.arc, truth_line.radius)
    err = np.abs(p.sections.diameter - analytic)
    voxel = min(stenosis.spacing)
    print(f"{source}: {len(err)} sections, |error| max {err.max():.3f} mm, p95 {np.percentile(err, 95):.3f} mm")
    assert err.max() <= 0.3 * voxel


@pytest.mark.parametrize("source", SOURCES)
def test_stenosis_within_five_points(stenosis, truth_line, profiles, source):
    """The 50 % diameter reduction read within 5 percentage points, at the narrowest point (within 3 mm), flagged."""
    st = profiles[source].stenosis
    truth = stenosis.meta["truth"]
    where = truth_line.project(truth["landmarks"]["stenosis"])[0]
    at = on_truth(truth_line, [profiles[source].centerline.at(st.arc)])[0]
    print(source, st)
    assert abs(st.percent - truth["stenosis"]) <= 5.0
    assert abs(at - where) <= 3.0
    assert st.flagged


@pytest.mark.parametrize("source", SOURCES)
def test_maximum_diameter_within_half_a_millimetre(stenosis, truth_line, profiles, source):
    """The aneurysm's 18 mm read within 0.5 mm, at its widest point (within 3 mm), flagged as an aneurysm."""
    mx = profiles[source].maximum
    truth = stenosis.meta["truth"]
    where = truth_line.project(truth["landmarks"]["aneurysm"])[0]
    at = on_truth(truth_line, [profiles[source].centerline.at(mx.arc)])[0]
    print(source, mx)
    assert abs(mx.diameter - truth["max_diameter"]) <= 0.5
    assert abs(at - where) <= 3.0
    assert mx.flagged and profiles[source].stenosis.kind == "stenosis"


@pytest.mark.parametrize("source", SOURCES)
def test_path_length_within_one_percent(truth_line, profiles, source):
    """The path's length against the true centerline's between the same ends; the tortuosity (length / chord - 1)
    within 2 % of the true path's."""
    p = profiles[source]
    a, b = on_truth(truth_line, p.centerline.points[[0, -1]])
    true_length = b - a
    chord = np.linalg.norm(truth_line.at(b) - truth_line.at(a))
    print(source, f"length {p.length:.2f} mm, truth {true_length:.2f} mm")
    assert abs(p.length - true_length) <= 0.01 * true_length
    assert abs(p.tortuosity - (true_length / chord - 1.0)) <= 0.02 * (true_length / chord - 1.0)


@pytest.mark.parametrize("source", SOURCES)
def test_inscribed_sphere_radius_against_the_analytic_ball(stenosis, truth_line, profiles, source):
    """The maximum inscribed sphere radius against the radius of the ball the phantom's tube is swept from:
    median within 0.4 voxel, 90th percentile within 0.6 voxel (a voxel mask's wall jitters by half a voxel,
    and the inscribed sphere meets its innermost points)."""
    p = profiles[source]
    ball = np.interp(on_truth(truth_line, p.centerline.points), truth_line.arc, stenosis.meta["truth"]["ball_radius"])
    err = np.abs(p.sections.inscribed_radius - ball)
    voxel = min(stenosis.spacing)
    print(source, f"median {np.median(err):.3f} mm, p90 {np.percentile(err, 90):.3f} mm")
    assert np.median(err) <= 0.4 * voxel and np.percentile(err, 90) <= 0.6 * voxel


def test_minimum_and_maximum_diameters_of_a_round_section_agree(profiles):
    """A round section's narrowest and widest extents lie within 0.4 voxel of its equivalent diameter, away from
    the lesions (the narrowest and widest of 180 extents of an outline drawn through 20 HU of noise); their
    directions are unit vectors orthogonal to the path."""
    p = profiles["grown"]
    s = p.sections
    healthy = np.abs(s.diameter - 10.0) < 0.3
    assert healthy.sum() > 100
    assert np.all(np.abs(s.max_diameter[healthy] - s.diameter[healthy]) <= 0.4)
    assert np.all(np.abs(s.min_diameter[healthy] - s.diameter[healthy]) <= 0.4)
    t = p.centerline.tangents
    for v in (s.min_direction, s.max_direction):
        assert np.allclose(np.linalg.norm(v, axis=1), 1.0, atol=1e-9)
        assert np.all(np.abs(np.einsum("ij,ij->i", v, t)) <= 1e-6)


def test_an_unbranched_artery_has_no_branch_points(profiles):
    for p in profiles.values():
        assert len(p.branch_arcs) == 0 and np.all(p.branch_count == 2)
