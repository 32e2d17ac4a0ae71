"""Collision detection for an eye moving inside a lumen: stop at a safety margin, slide along the wall.

A move of the eye from ``p`` by a motion vector ``m`` (world mm) goes like this
(compiled, :func:`_move`):

1. the motion is capped at ``max_length`` mm;
2. a ray is marched from ``p`` along ``m`` for ``|m| + margin`` mm; a wall met
   at ``t`` (crossing interpolated between the two samples around it) allows
   at most ``t - margin``;
3. the swept eye is checked every ``margin / 2`` mm and at the end: a point is
   *clear* when no probe ray (evenly spread directions) meets the wall within
   ``margin - tolerance`` mm; at the first point that is not clear the move
   is cut back by bisection to the last clear point (to 0.01 mm);
4. when blocked and ``slide`` is on, what remains of the motion is projected
   onto the wall's tangent plane (normal = the field's gradient where the
   wall was met) and moved with the same checks, in sub-steps of half the
   margin; after each the eye is pushed back out to the margin from the
   nearest wall and the direction is projected again, so the slide follows
   curved walls (collide-and-slide).

An eye that starts closer than the margin (placed there by hand) may move,
but never closer to the wall than it was.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ...jit import njit
from ..wall._field import WallField
from ..wall._first_hit import NO_HIT, Wall, fibonacci_directions, first_hit, probe, wall_gradient

__all__ = ["Collider", "MoveResult"]

FREE, SLID, STOPPED = 0, 1, 2


class Keep(NamedTuple):
    """What the collision kernels keep the eye away from, as one record (Numba compiles it as a struct)."""

    wall: Wall         #: the wall field, its geometry, level and marching step
    dirs: np.ndarray   #: probe directions (n, 3), unit vectors spread over the sphere
    margin: float      #: safety distance, mm
    tol: float         #: a point is clear when no probe meets the wall within ``margin - tol`` mm


@njit(cache=True)
def _clear(c, p, need):
    t, k = probe(c.wall, p, c.dirs, need)
    return t >= need, t, k


@njit(cache=True)
def _advance(c, p, d, length, out):
    """Move from ``p`` along unit ``d`` (tuples, world mm) by up to ``length`` mm, keeping ``c`` (:class:`Keep`).

    Writes the wall normal met (or zeros) into ``out[0:3]``; returns the distance moved (mm).
    """
    w, dirs, margin, tol = c.wall, c.dirs, c.margin, c.tol
    px, py, pz = p
    dx, dy, dz = d
    out[0] = 0.0
    out[1] = 0.0
    out[2] = 0.0
    if length <= 0.0:
        return 0.0
    # how clear must the eye stay: the margin, or what it has when it starts closer
    ok0, t0, k0 = _clear(c, p, margin - tol)
    need = margin - tol if ok0 else t0
    th = first_hit(w, p, d, length + margin)
    s = length
    wx = 0.0
    wy = 0.0
    wz = 0.0
    have_wall = False
    if th < NO_HIT:
        s = min(length, max(th - margin, 0.0))
        if s < length:
            wx, wy, wz = px + th * dx, py + th * dy, pz + th * dz
            have_wall = True
    # sweep: the first point that is not clear, every margin / 2 and at the end
    h = max(0.5 * margin, w.step)
    good = 0.0
    bad = -1.0
    kbad = -1
    q = h
    while True:
        q = min(q, s)
        ok, t, k = _clear(c, (px + q * dx, py + q * dy, pz + q * dz), need)
        if not ok:
            bad = q
            kbad = k
            break
        good = q
        if q >= s:
            break
        q += h
    if bad >= 0.0:
        while bad - good > 0.01:
            mid = 0.5 * (good + bad)
            ok, t, k = _clear(c, (px + mid * dx, py + mid * dy, pz + mid * dz), need)
            if ok:
                good = mid
            else:
                bad = mid
                kbad = k
        s = good
        if kbad >= 0:
            cx, cy, cz = px + bad * dx, py + bad * dy, pz + bad * dz
            tw = first_hit(w, (cx, cy, cz), (dirs[kbad, 0], dirs[kbad, 1], dirs[kbad, 2]), margin)
            if tw < NO_HIT:
                wx, wy, wz = cx + tw * dirs[kbad, 0], cy + tw * dirs[kbad, 1], cz + tw * dirs[kbad, 2]
                have_wall = True
    if have_wall and s < length:
        gx, gy, gz = wall_gradient(w, (wx, wy, wz))
        g = np.sqrt(gx * gx + gy * gy + gz * gz)
        if g > 0.0:
            out[0] = -gx / g  # into the lumen
            out[1] = -gy / g
            out[2] = -gz / g
    return s


@njit(cache=True)
def _slide(c, p, t, length, nrm):
    """Slide the eye ``p`` (3,, updated in place) along the wall by ``length`` mm, starting along unit ``t`` (tuple).

    The slide goes in sub-steps of ``margin / 2``; each is checked like a move, then the eye is
    pushed back out to the margin from the nearest wall (so it follows curved walls), and the
    direction is projected again onto the tangent plane of that wall (normal ``nrm``, into the lumen).
    Returns the length slid (mm).
    """
    dirs, margin, tol = c.dirs, c.margin, c.tol
    tx, ty, tz = t
    h = max(0.5 * margin, c.wall.step)
    n_sub = int(np.ceil(length / h))
    sub = length / n_sub
    done = 0.0
    need = margin - tol
    for _ in range(n_sub):
        s = _advance(c, (p[0], p[1], p[2]), (tx, ty, tz), sub, nrm)
        qx, qy, qz = p[0] + s * tx, p[1] + s * ty, p[2] + s * tz
        done += s
        if s < sub - 1e-9:
            # blocked in this sub-step: turn along the wall that stopped it, or give up
            cn = tx * nrm[0] + ty * nrm[1] + tz * nrm[2]
            if cn >= 0.0 or (nrm[0] == 0.0 and nrm[1] == 0.0 and nrm[2] == 0.0):
                p[0], p[1], p[2] = qx, qy, qz
                break
            ux, uy, uz = tx - cn * nrm[0], ty - cn * nrm[1], tz - cn * nrm[2]
            ul = np.sqrt(ux * ux + uy * uy + uz * uz)
            if ul < 1e-6:
                p[0], p[1], p[2] = qx, qy, qz
                break
            tx, ty, tz = ux / ul, uy / ul, uz / ul
        # push out from the nearest wall to a little beyond the margin, if that spot is clear
        tn, k = probe(c.wall, (qx, qy, qz), dirs, margin + 4 * tol)
        if k >= 0 and tn < margin + 2 * tol:
            push = margin + 2 * tol - tn
            rx, ry, rz = qx - push * dirs[k, 0], qy - push * dirs[k, 1], qz - push * dirs[k, 2]
            ok, t2, k2 = _clear(c, (rx, ry, rz), need)
            if ok:
                qx, qy, qz = rx, ry, rz
        p[0], p[1], p[2] = qx, qy, qz
    return done


@njit(cache=True)
def _move(c, p, m, max_length, slide, out):
    """Move the eye ``p`` (3,) by ``m`` (3,) mm keeping ``c`` (:class:`Keep`); write the new position into ``out``.

    Returns ``(status, moved)``: FREE / SLID / STOPPED and the length moved (mm): along the
    motion, plus along the wall when sliding (the small push-outs from the wall not counted).
    """
    out[0], out[1], out[2] = p[0], p[1], p[2]
    length = np.sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2])
    if length == 0.0:
        return FREE, 0.0
    dx, dy, dz = m[0] / length, m[1] / length, m[2] / length
    length = min(length, max_length)
    nrm = np.zeros(3)
    s = _advance(c, (p[0], p[1], p[2]), (dx, dy, dz), length, nrm)
    out[0] += s * dx
    out[1] += s * dy
    out[2] += s * dz
    if s >= length - 1e-9:
        return FREE, s
    # what remains, projected onto the tangent plane of the wall that blocked it
    cn = dx * nrm[0] + dy * nrm[1] + dz * nrm[2]
    rem = length - s
    if not slide or cn >= 0.0 or (nrm[0] == 0.0 and nrm[1] == 0.0 and nrm[2] == 0.0):
        return STOPPED, s
    tx, ty, tz = dx - cn * nrm[0], dy - cn * nrm[1], dz - cn * nrm[2]
    tl = np.sqrt(tx * tx + ty * ty + tz * tz)
    if tl * rem < 1e-6:
        return STOPPED, s
    slid = _slide(c, out, (tx / tl, ty / tl, tz / tl), tl * rem, nrm)
    return (SLID if slid > 0.0 else STOPPED), s + slid


@dataclass(frozen=True)
class MoveResult:
    """Outcome of :meth:`Collider.move`.

    Attributes
    ----------
    position : (3,) float, world mm
        Where the eye ends.
    moved : float, mm
        Length travelled: along the motion, plus along the wall when sliding
        (at most the motion's length).
    blocked : bool
        The wall stopped at least part of the motion.
    slid : bool
        Part of the blocked motion was turned along the wall.
    """

    position: np.ndarray
    moved: float
    blocked: bool
    slid: bool


class Collider:
    """Keeps an eye at least ``margin`` mm from the wall of a :class:`WallField`.

    Parameters
    ----------
    wall : WallField
    margin : float, mm
        Safety distance between the eye and the wall (keep it larger than the
        camera's near plane so the wall is never clipped).
    max_length : float, mm
        Longest motion of one move (longer motions are shortened to it).
    slide : bool
        Turn blocked motion along the wall instead of stopping dead.
    directions : int
        Probe rays of the clearance test, spread evenly on the sphere (98:
        nearest direction within ~13 degrees, distance overestimated < 3 %).
    tolerance : float, mm
        A point is clear when no probe meets the wall within ``margin - tolerance``.
    step : float or None, mm
        Marching step (default: half the smallest voxel spacing).
    """

    def __init__(self, wall: WallField, *, margin: float = 2.0, max_length: float = 50.0, slide: bool = True,
                 directions: int = 98, tolerance: float = 0.02, step: float | None = None):
        if not isinstance(wall, WallField):
            raise ValueError(f"wall must be a WallField, got {type(wall).__name__}")
        if not (np.isfinite(margin) and margin > 0):
            raise ValueError(f"margin must be > 0 mm, got {margin}")
        if not (np.isfinite(max_length) and max_length > 0):
            raise ValueError(f"max_length must be > 0 mm, got {max_length}")
        if directions < 6:
            raise ValueError(f"directions must be >= 6, got {directions}")
        if not 0 <= tolerance < margin:
            raise ValueError(f"tolerance must be in [0, margin), got {tolerance}")
        self.wall = wall
        self.margin = float(margin)
        self.max_length = float(max_length)
        self.slide = bool(slide)
        self.tolerance = float(tolerance)
        self.step = float(wall.step if step is None else step)
        if not self.step > 0:
            raise ValueError(f"step must be > 0 mm, got {step}")
        self.directions = fibonacci_directions(int(directions))
        self._wall = Wall(wall.field, wall.geometry, wall.level, self.step)
        self._keep = Keep(self._wall, self.directions, self.margin, self.tolerance)

    def first_hit(self, origin, direction, max_length: float) -> float:
        """Distance (mm) from ``origin`` along ``direction`` (world, any length) to the wall; inf if none within
        ``max_length``."""
        o = np.asarray(origin, float)
        d = np.asarray(direction, float)
        d = d / np.linalg.norm(d)
        t = first_hit(self._wall, (o[0], o[1], o[2]), (d[0], d[1], d[2]), float(max_length))
        return float("inf") if t >= NO_HIT else float(t)

    def clearance(self, point, radius: float | None = None) -> float:
        """Distance (mm) to the nearest wall seen by the probe rays, inf beyond ``radius`` (default 4 margins)."""
        p = np.asarray(point, float)
        r = 4 * self.margin if radius is None else float(radius)
        t, _ = probe(self._wall, (p[0], p[1], p[2]), self.directions, r)
        return float("inf") if t >= NO_HIT else float(t)

    def is_clear(self, point) -> bool:
        """True when the eye at ``point`` is at least ``margin - tolerance`` mm from the wall."""
        return self.clearance(point, self.margin) >= self.margin - self.tolerance

    def normal(self, point) -> np.ndarray:
        """Unit wall normal at a world ``point`` near the wall, pointing into the lumen (zeros where flat)."""
        p = np.asarray(point, float)
        g = np.array(wall_gradient(self._wall, (p[0], p[1], p[2])))
        n = np.linalg.norm(g)
        return -g / n if n > 0 else g

    def move(self, position, motion) -> MoveResult:
        """Move the eye at ``position`` by ``motion`` (both (3,) world mm) as far as the wall allows."""
        p = np.ascontiguousarray(position, np.float64).reshape(3)
        m = np.ascontiguousarray(motion, np.float64).reshape(3)
        if not (np.all(np.isfinite(p)) and np.all(np.isfinite(m))):
            raise ValueError("position and motion must be finite (x, y, z) mm")
        out = np.empty(3)
        status, moved = _move(self._keep, p, m, self.max_length, self.slide, out)
        return MoveResult(position=out, moved=float(moved), blocked=status != FREE, slid=status == SLID)
