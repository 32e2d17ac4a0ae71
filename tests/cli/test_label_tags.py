"""The names on ``volumen slices --labels`` (``cli._label_tags.place_tags``): each inside its structure, none over
another, the largest structures named first; an atlas too dense for all its names shows the ones with room."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from volumen.cli._label_tags import MARGIN, place_tags


def _apart(a, b) -> bool:
    """Boxes (x0, y0, x1, y1) at least MARGIN pixels apart along x or y."""
    return a[2] + MARGIN <= b[0] or b[2] + MARGIN <= a[0] or a[3] + MARGIN <= b[1] or b[3] + MARGIN <= a[1]


def _check(lab, placed, sizes):
    h, w = lab.shape
    for (v, _, box), (_, _, other) in itertools.combinations(placed, 2):
        assert _apart(box, other), (v, box, other)
    for v, (x, y), (x0, y0, x1, y1) in placed:
        assert lab[int(y), int(x)] == v, "a name's centre lies outside its structure"
        assert 0 <= x0 and 0 <= y0 and x1 <= w and y1 <= h
        assert (x1 - x0, y1 - y0) == pytest.approx(sizes[v])


def test_a_dense_atlas_names_the_structures_there_is_room_for_without_overlap():
    """A 12 x 12 grid of 10-pixel squares with names 30 x 8 pixels: at most one name in three columns fits."""
    lab = np.kron(np.arange(1, 145).reshape(12, 12), np.ones((10, 10), int))
    sizes = {v: (30.0, 8.0) for v in range(1, 145)}
    placed = place_tags(lab, list(sizes), sizes)
    _check(lab, placed, sizes)
    assert 20 <= len(placed) < 144


def test_two_structures_side_by_side_both_named_and_the_largest_first():
    """A ring (its centroid outside it) and a small disc inside it: each name inside its own structure."""
    yy, xx = np.mgrid[:120, :120]
    r = np.hypot(yy - 60, xx - 60)
    lab = np.where((r > 35) & (r < 55), 1, 0) + np.where(r < 18, 2, 0)
    sizes = {1: (40.0, 10.0), 2: (24.0, 10.0)}
    placed = place_tags(lab, [2, 1], sizes)
    _check(lab, placed, sizes)
    assert [v for v, _, _ in placed] == [1, 2]
