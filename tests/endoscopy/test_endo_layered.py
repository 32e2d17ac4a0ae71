"""The start-point sweep on the layered-aorta phantom: a large contrast vessel whose contrast is layered and mixed
with a jet of unopacified blood (100-480 HU), correlated noise of 40 HU, lung 10 mm away, a bright neighbour
touching it. From 20 starts along it (up to half its radius off the axis, one in the jet), each pair flown both
ways as ``volumen fly`` plans a flight: every one flies (no refusal), and none leaves its lumen."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

from volumen.endoscopy import checked_centerline, keyframes_inside, lumen_wall, make_flight

PAIRS = [(i, i + 10) for i in range(10)] + [(i + 10, i) for i in range(10)]


@pytest.fixture(scope="module")
def layered():
    from volumen.data import phantom

    return phantom("layered_aorta")


@pytest.mark.parametrize("a, b", PAIRS, ids=[f"{a}-{b}" for a, b in PAIRS])
def test_every_start_flies_inside_its_lumen(layered, a, b):
    """Grown lumen: 98 % of it within 2 voxels of the true lumen, none of it in the neighbour or the lung; the
    centerline and every keyframe inside the true lumen; the wall threshold between the fat (-90 HU) and the
    contrast's darkest layer (300 HU)."""
    truth = layered.meta["truth"]
    starts = np.array(truth["landmarks"]["starts"])
    lumen = truth["aorta"].mask
    wall = lumen_wall(layered, starts[a], starts[b])
    cl = checked_centerline(layered, wall.mask, starts[a], starts[b])
    flight = make_flight(layered, wall, cl)
    near = ndimage.binary_dilation(lumen, iterations=2)
    grown = wall.mask
    est = wall.estimate
    print(est.describe(), f"radius {cl.radius.min():.1f}..{cl.radius.max():.1f} mm")
    assert est.kind == "contrast" and -90.0 < est.threshold < 300.0
    assert (grown & near).sum() >= 0.98 * grown.sum()
    assert not (grown & truth["neighbour"]).any() and not (grown & truth["lung"]).any()
    ijk = np.rint(layered.world_to_index(cl.points)[:, ::-1]).astype(int)
    assert lumen[tuple(ijk.T)].all()
    assert keyframes_inside(layered, lumen, flight.path) == 1.0
