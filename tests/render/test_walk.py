"""The block walk of empty-space skipping (``raycast._walk``), a 3-D DDA through the skipping
grid: on random rays it visits, in order, every block a dense sampling of the ray meets, and each block it visits
holds the ray over the interval it gives it (no block the ray misses); a jump past a cube of empty blocks leaves
the ray on the cube's face; the octant skip sides (``raycast._octants``) are the largest empty cubes ahead of the
ray, and a jump by one passes over no block that can contribute. That skipping changes no picture, for every
mode, is ``test_acceleration``'s."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit
from scipy import ndimage

from volumen.render.raycast._frame import FAR
from volumen.render.raycast._octants import octant_sides, tiled
from volumen.render.raycast._ray import Ray
from volumen.render.raycast._walk import _past, enter

BLOCK = 4
GRID = (7, 6, 5)  # blocks along z, y, x


class _Arrays(NamedTuple):
    bmin: np.ndarray


class _Settings(NamedTuple):
    block: int


@njit(cache=False)
def _walk_all(r, a, s, t, rad, out):
    """From the block at ray parameter ``t``, ``_past`` with radius ``rad`` until no block is left: rows
    ``(bk, bj, bi, entry t)``, the first with entry ``t``; the number of rows."""
    bk, bj, bi = enter(r, a, s, t)
    n = 0
    while t < FAR / 2 and n < out.shape[0]:
        out[n, 0], out[n, 1], out[n, 2], out[n, 3] = bk, bj, bi, t
        n += 1
        bk, bj, bi, t = _past(r, a, s, bk, bj, bi, rad)
    return n


def _ray(rng):
    """A random ray through the grid's box (index space, t in index units), with its entry and exit."""
    top = np.array(GRID[::-1], float) * BLOCK  # x, y, z
    while True:
        o = rng.uniform(-20, top + 20)
        d = rng.normal(size=3)
        d /= np.linalg.norm(d)
        if rng.random() < 0.3:
            d[rng.integers(3)] = 0.0  # a ray parallel to a face
            d /= np.linalg.norm(d)
        with np.errstate(divide="ignore", invalid="ignore"):
            ta, tb = (0 - o) / d, (top - o) / d
        lo = np.where(d != 0, np.minimum(ta, tb), -np.inf)
        hi = np.where(d != 0, np.maximum(ta, tb), np.inf)
        lo = np.where((d == 0) & ((o < 0) | (o > top)), np.inf, lo)
        t0, t1 = lo.max(), hi.min()
        if t1 - t0 > 1.0:
            r = Ray(0, 0, 0, 0, 0, 0, o[0], o[1], o[2], d[0], d[1], d[2], t0, t1, 0.0, 1, 0, 1, 0.0)
            return r, t0, t1


def _dense_blocks(r, t0, t1):
    """The blocks a dense sampling of the ray meets, in order."""
    t = np.linspace(t0, t1, 20001)[1:-1]
    p = np.stack([r.ok + t * r.dk, r.oj + t * r.dj, r.oi + t * r.di], 1)
    b = np.clip((p // BLOCK).astype(int), 0, np.array(GRID) - 1)
    keep = np.r_[True, (np.diff(b, axis=0) != 0).any(1)]
    return [tuple(v) for v in b[keep]]


def test_the_walk_visits_exactly_the_blocks_the_ray_passes_through():
    rng = np.random.default_rng(7)
    a, s = _Arrays(np.zeros(GRID, np.uint8)), _Settings(BLOCK)
    out = np.zeros((200, 4))
    for _ in range(300):
        r, t0, t1 = _ray(rng)
        n = _walk_all(r, a, s, t0 + 1e-9, 1, out)
        rows = out[:n][out[:n, 3] < t1]  # the walk stops where the ray leaves the volume
        walked = [tuple(int(v) for v in row[:3]) for row in rows]
        dense = _dense_blocks(r, t0, t1)
        assert [b for b in walked if b in set(dense)] == dense  # every block met, in order, none twice
        exits = np.r_[rows[1:, 3], t1]
        assert np.all(np.diff(rows[:, 3]) > 0)
        for (bk, bj, bi), ta, tb in zip(walked, rows[:, 3], exits, strict=True):
            tm = 0.5 * (ta + min(tb, t1))  # the ray's own interval in the block lies in it
            p = np.array([r.ok + tm * r.dk, r.oj + tm * r.dj, r.oi + tm * r.di])
            lo = np.array([bk, bj, bi]) * BLOCK
            assert np.all(p >= lo - 1e-9) and np.all(p <= lo + BLOCK + 1e-9), (walked, p)


def test_a_jump_leaves_the_ray_on_the_far_face_of_the_cube_of_empty_blocks():
    rng = np.random.default_rng(11)
    a, s = _Arrays(np.zeros(GRID, np.uint8)), _Settings(BLOCK)
    jumps = 0
    for _ in range(300):
        r, t0, t1 = _ray(rng)
        b = np.array(enter(r, a, s, t0 + 1e-9))
        bk, bj, bi, te = _past(r, a, s, *[int(v) for v in b], 2)
        if te >= t1:
            continue  # the ray leaves the volume inside the cube
        jumps += 1
        p = np.array([r.ok + te * r.dk, r.oj + te * r.dj, r.oi + te * r.di])
        lo, hi = (b - 1) * BLOCK, (b + 2) * BLOCK  # the cube of radius 2: blocks b - 1 .. b + 1
        assert np.all(p >= lo - 1e-9) and np.all(p <= hi + 1e-9)
        assert np.isclose(np.minimum(np.abs(p - lo), np.abs(p - hi)), 0, atol=1e-9).any()  # on a face
        step = np.abs(np.array([bk, bj, bi]) - b)
        assert step.max() == 2  # the exit axis moved by the radius, past the cube
    assert jumps > 100


def _largest_empty_cube(flags, b, signs):
    """Brute force: the side of the largest cube of blocks with no flag set that starts at block ``b`` and
    extends the ``signs`` way, blocks past the grid counting as empty (capped at 255)."""
    side = 0
    while side < 255:
        lo = [c if s > 0 else c - side for c, s in zip(b, signs, strict=True)]
        box = tuple(slice(max(a, 0), max(a + side + 1, 0)) for a in lo)
        if flags[box].any():
            break
        side += 1
        if all((a + side > g if s > 0 else a - 1 < 0) for a, s, g in zip(lo, signs, flags.shape, strict=True)):
            return 255  # the cube has left the grid on every axis: nothing ahead can stop it
    return side


def test_octant_sides_are_the_largest_empty_cubes_ahead_and_their_least_is_the_chebyshev_distance():
    rng = np.random.default_rng(5)
    for density in (0.02, 0.15):
        flags = (rng.random((9, 7, 11)) < density).astype(np.uint8)
        sides = octant_sides(flags)
        chebyshev = np.minimum(ndimage.distance_transform_cdt(flags == 0, metric="chessboard"), 255)
        assert np.array_equal(sides.min(axis=0), chebyshev)
        for o in range(8):
            signs = (-1 if o & 4 else 1, -1 if o & 2 else 1, -1 if o & 1 else 1)
            for b in np.ndindex(flags.shape):
                assert sides[(o, *b)] == _largest_empty_cube(flags, b, signs), (o, b)


def test_an_octant_jump_passes_over_no_block_that_can_contribute():
    rng = np.random.default_rng(13)
    flags = (rng.random(GRID) < 0.08).astype(np.uint8)
    sides = octant_sides(flags)
    a, s = _Arrays(np.zeros(GRID, np.float32)), _Settings(BLOCK)
    jumps = 0
    for _ in range(400):
        r, t0, t1 = _ray(rng)
        o = (4 if r.dk < 0 else 0) + (2 if r.dj < 0 else 0) + (1 if r.di < 0 else 0)
        t = t0 + 1e-9
        b = enter(r, a, s, t)
        while t < t1:
            rad = int(sides[(o, *b)])
            *nb, te = _past(r, a, s, *b, max(rad, 1))
            if rad > 1:
                jumps += 1
                seg = np.linspace(t, min(te, t1), 2002)[1:-1]  # inside the interval: its ends lie on faces
                p = np.stack([r.ok + seg * r.dk, r.oj + seg * r.dj, r.oi + seg * r.di], 1)
                met = np.clip((p // BLOCK).astype(int), 0, np.array(GRID) - 1)
                assert not flags[tuple(met.T)].any()
            b, t = tuple(int(v) for v in nb), te
    assert jumps > 200


def test_the_gl_texture_holds_each_octant_at_its_offset():
    sides = np.random.default_rng(3).integers(0, 256, (8, 3, 4, 5)).astype(np.uint8)
    t = tiled(sides)
    assert t.shape == (6, 8, 10)
    for o in range(8):
        dz, dy, dx = (3 if o & 4 else 0), (4 if o & 2 else 0), (5 if o & 1 else 0)
        assert np.array_equal(t[dz:dz + 3, dy:dy + 4, dx:dx + 5], sides[o])
