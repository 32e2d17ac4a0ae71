"""cut_bridges: two balls joined by a thin rod come apart; a wide neck stays; the result is a subset."""

from __future__ import annotations

import numpy as np

from volumen.segment import cut_bridges


def _dumbbell(rod: float):
    z, y, x = np.mgrid[:30, :30, :70].astype(float)
    a = np.hypot(np.hypot(z - 15, y - 15), x - 15) <= 10
    b = np.hypot(np.hypot(z - 15, y - 15), x - 55) <= 10
    bar = (np.hypot(z - 15, y - 15) <= rod) & (x >= 15) & (x <= 55)
    return a | b | bar, a, b


def test_thin_bridge_is_cut_and_the_seeded_ball_kept_whole():
    """A rod of radius 1 mm between two balls of radius 10 mm (1 mm voxels), radius 2 mm: the seeded ball is kept
    entirely, the other one not at all, and at most a 2.5 mm stub of the rod."""
    mask, a, b = _dumbbell(1.0)
    out = cut_bridges(mask, (1.0, 1.0, 1.0), [(15, 15, 15)], 2.0)
    stub = out & ~a
    print(f"kept {out.sum()} of {mask.sum()} voxels; ball A {np.sum(out & a)} / {a.sum()}, ball B {np.sum(out & b)}")
    assert np.all(out <= mask) and np.array_equal(out & a, a) and not np.any(out & b)
    assert stub.any() and np.argwhere(stub)[:, 2].max() <= 25 + 2.5


def test_wide_neck_and_zero_radius_keep_everything():
    mask, _, _ = _dumbbell(4.0)
    assert np.array_equal(cut_bridges(mask, (1.0, 1.0, 1.0), [(15, 15, 15)], 2.0), mask)
    thin, _, _ = _dumbbell(1.0)
    assert np.array_equal(cut_bridges(thin, (1.0, 1.0, 1.0), [(15, 15, 15)], 0.0), thin)
