"""The cross-section measures on shapes with answers in closed form: an elliptic cylinder (area, Feret's diameters
and their directions, the inscribed circle), branch points on the airways phantom's bronchial tree, and the
stenosis and maximum of diameter profiles made up to order."""

from __future__ import annotations

import numpy as np
import pytest

from volumen.core import Volume


def _straight_line(length: float, z0: float, x: float, y: float):
    from volumen.endoscopy import Centerline

    z = np.arange(0.0, length + 1e-9, 1.0)
    pts = np.stack([np.full_like(z, x), np.full_like(z, y), z0 + z], axis=1)
    return Centerline(pts, np.full(len(z), 3.0), z)


@pytest.mark.parametrize("spacing", [(1.0, 0.5, 0.5), (1.5, 0.8, 0.8)])
def test_elliptic_cylinder(spacing):
    """Semi-axes 6 and 3.5 mm along x and y: area pi a b within 2 %, Feret's diameters 2a and 2b within 0.25 mm along
    x and y (within 3 degrees), the inscribed sphere's radius b within 0.25 mm."""
    from volumen.analysis._sections import measure_sections

    a, b = 6.0, 3.5
    shape = (32, 48, 48)
    vol = Volume(np.zeros(shape, np.int16), spacing=spacing)
    kk, jj, ii = np.indices(shape)
    world = vol.index_to_world(np.stack([ii, jj, kk], axis=-1).reshape(-1, 3).astype(float)).reshape(*shape, 3)
    cx, cy = world[0, 24, 24, 0] + 0.3, world[0, 24, 24, 1] + 0.2
    lumen = ((world[..., 0] - cx) / a) ** 2 + ((world[..., 1] - cy) / b) ** 2 < 1.0
    z0 = world[0, 0, 0, 2]
    cl = _straight_line(spacing[0] * (shape[0] - 1) - 8.0, z0 + 4.0, cx, cy)
    s = measure_sections(vol, lumen, cl)
    assert np.all(np.abs(s.area / (np.pi * a * b) - 1.0) <= 0.02)
    assert np.all(np.abs(s.max_diameter - 2 * a) <= 0.25) and np.all(np.abs(s.min_diameter - 2 * b) <= 0.25)
    cos3 = np.cos(np.deg2rad(3.0))
    assert np.all(np.abs(s.max_direction[:, 0]) >= cos3) and np.all(np.abs(s.min_direction[:, 1]) >= cos3)
    assert np.all(np.abs(s.inscribed_radius - b) <= 0.25)


def test_branch_points_of_the_bronchial_tree():
    """Along the trachea and right bronchi of the airways phantom (its true lumen, branches included): the carina,
    the right upper and the right middle lobar bronchi's origins, each found within 3 mm, nothing else."""
    from volumen.analysis._branches import branch_points
    from volumen.data import phantom
    from volumen.endoscopy import Centerline

    vol = phantom("airways")
    tube = vol.meta["truth"]["airway"]
    cl = Centerline(tube.centerline, tube.radius, tube.arc_length)
    _, arcs = branch_points(vol, tube.mask, cl, tube.radius)
    origins = {b.name: cl.project(b.centerline[0])[0] for b in tube.branches
               if b.name in ("left_main_lower", "right_upper", "right_middle")}
    print("found", np.round(arcs, 1), "origins", origins)
    assert len(arcs) == 3
    for name, where in origins.items():
        assert np.min(np.abs(arcs - where)) <= 3.0, name


def test_lesions_of_a_profile_made_to_order():
    """A 10 mm vessel narrowed to 6 mm (40 %) over 10 mm and widened to 15 mm over 20 mm: both found where they
    are, with their percentages exact; a 15 % dip is not flagged as a stenosis."""
    from volumen.analysis._lesions import find_maximum, find_stenosis

    arc = np.arange(0.0, 200.0, 1.0)
    d = np.full(arc.shape, 10.0)
    d[(arc >= 50) & (arc < 60)] = 6.0
    d[(arc >= 120) & (arc < 140)] = 15.0
    none, seg = np.zeros(arc.shape, bool), np.zeros(arc.shape, int)
    st = find_stenosis(arc, d, none, seg)
    mx = find_maximum(arc, d, d, none, seg)
    assert st.extent == (50.0, 59.0) and st.percent == pytest.approx(40.0) and st.flagged
    assert mx.extent == (120.0, 139.0) and mx.percent == pytest.approx(50.0) and mx.flagged
    mild = np.full(arc.shape, 10.0)
    mild[(arc >= 50) & (arc < 60)] = 8.5
    weak = find_stenosis(arc, mild, none, seg)
    assert weak.percent == pytest.approx(15.0) and not weak.flagged
