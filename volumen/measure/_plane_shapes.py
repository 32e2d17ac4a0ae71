"""Slice planes in world millimetres and the shapes of regions drawn on them.

A :class:`Plane` is an origin and two orthonormal in-plane directions ``u`` and ``v`` (world RAS+ mm, docs/design.md
section 2); its normal is ``u x v``. A shape (:class:`Ellipse`, :class:`Rectangle`, :class:`Polygon`) lives in the
plane's own coordinates ``(s, t)`` in mm: the world point of ``(s, t)`` is ``origin + s u + t v``. The named slices
of a volume (axial, coronal, sagittal) are the planes of its voxel axes (:func:`slice_plane`), so a region drawn on
a slice view covers whole voxels of that slice.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core import axis_codes

__all__ = ["Plane", "Ellipse", "Rectangle", "Polygon", "SHAPES", "slice_plane", "shape_from_dict"]

#: the anatomical axis each named plane is normal to, as the letters of ``axis_codes``
_NORMAL_LETTERS = {"axial": "SI", "coronal": "AP", "sagittal": "RL"}


def _unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=float)
    n = float(np.linalg.norm(v))
    if not np.isfinite(n) or n == 0.0:
        raise ValueError(f"a plane direction must be a finite non-zero vector, got {v.tolist()}")
    return v / n


@dataclass(frozen=True)
class Plane:
    """A plane in world RAS+ mm: ``origin`` and in-plane unit directions ``u``, ``v`` (made orthonormal)."""

    origin: tuple[float, float, float]
    u: tuple[float, float, float]
    v: tuple[float, float, float]

    def __post_init__(self):
        u, v = np.asarray(self.u, float), np.asarray(self.v, float)
        orthonormal = np.allclose([u @ u, v @ v, u @ v], [1.0, 1.0, 0.0], rtol=0, atol=1e-14)
        if not orthonormal:  # made so once: a plane read back from JSON keeps its numbers to the last bit
            u = _unit(u)
            v = _unit(v - np.dot(v, u) * u)
        object.__setattr__(self, "origin", tuple(float(x) for x in self.origin))
        object.__setattr__(self, "u", tuple(u.tolist()))
        object.__setattr__(self, "v", tuple(v.tolist()))

    @classmethod
    def through(cls, origin, normal) -> Plane:
        """The plane through ``origin`` with ``normal``; ``u`` is the world axis least along the normal, made
        perpendicular to it."""
        n = _unit(normal)
        seed = np.eye(3)[int(np.argmin(np.abs(n)))]
        u = seed - np.dot(seed, n) * n
        return cls(origin, u, np.cross(n, _unit(u)))

    @property
    def normal(self) -> np.ndarray:
        return np.cross(self.u, self.v)

    def to_world(self, st) -> np.ndarray:
        """Plane coordinates ``(..., 2)`` mm -> world RAS+ mm ``(..., 3)``."""
        st = np.asarray(st, dtype=float)
        return np.asarray(self.origin) + st[..., :1] * np.asarray(self.u) + st[..., 1:2] * np.asarray(self.v)

    def to_plane(self, xyz) -> tuple[np.ndarray, np.ndarray]:
        """World points ``(..., 3)`` -> ``(st (..., 2), signed distance (...))`` in mm from the plane."""
        d = np.asarray(xyz, dtype=float) - np.asarray(self.origin)
        st = np.stack([d @ np.asarray(self.u), d @ np.asarray(self.v)], axis=-1)
        return st, d @ self.normal

    def to_dict(self) -> dict:
        return {"origin": list(self.origin), "u": list(self.u), "v": list(self.v)}

    @classmethod
    def from_dict(cls, d: dict) -> Plane:
        return cls(tuple(d["origin"]), tuple(d["u"]), tuple(d["v"]))


def slice_plane(volume, plane: str, index: int) -> Plane:
    """The plane of slice ``index`` of ``volume`` along the voxel axis nearest the named anatomical ``plane``
    (axial, coronal, sagittal), through that slice's voxel centres; ``u`` and ``v`` are the other two voxel axes."""
    if plane not in _NORMAL_LETTERS:
        from ..errors import UnknownChoiceError

        raise UnknownChoiceError("plane", plane, tuple(_NORMAL_LETTERS))
    codes = axis_codes(volume.affine)
    axis = next(a for a in range(3) if codes[a] in _NORMAL_LETTERS[plane])
    ijk = np.zeros(3)
    ijk[axis] = index
    cols = [volume.affine[:3, a] for a in range(3) if a != axis]
    return Plane(tuple(volume.index_to_world(ijk)), tuple(cols[0]), tuple(cols[1]))


@dataclass(frozen=True)
class Ellipse:
    """An ellipse in plane coordinates: ``center`` (s, t) mm and semi-axes ``radii`` (along s, along t) mm."""

    center: tuple[float, float]
    radii: tuple[float, float]
    kind = "ellipse"

    def contains(self, st: np.ndarray) -> np.ndarray:
        d = (st - np.asarray(self.center)) / np.asarray(self.radii, float)
        return (d**2).sum(axis=-1) <= 1.0

    @property
    def area(self) -> float:
        return float(np.pi * self.radii[0] * self.radii[1])

    def outline(self) -> np.ndarray:
        """The four ends of the axes (DICOM's ELLIPSE: the first axis's two ends, then the second's)."""
        (cs, ct), (a, b) = self.center, self.radii
        return np.array([[cs - a, ct], [cs + a, ct], [cs, ct - b], [cs, ct + b]], float)

    def bounds(self) -> np.ndarray:
        c, r = np.asarray(self.center, float), np.asarray(self.radii, float)
        return np.array([c - r, c + r])

    def to_dict(self) -> dict:
        return {"kind": self.kind, "center": list(self.center), "radii": list(self.radii)}


@dataclass(frozen=True)
class Polygon:
    """A closed polygon in plane coordinates: ``points`` ((s, t) mm, not repeating the first at the end)."""

    points: tuple[tuple[float, float], ...]
    kind = "polygon"

    def __post_init__(self):
        pts = np.asarray(self.points, float)
        if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 3:
            raise ValueError(f"a polygon needs at least three (s, t) points, got shape {pts.shape}")
        object.__setattr__(self, "points", tuple(map(tuple, pts.tolist())))

    def contains(self, st: np.ndarray) -> np.ndarray:
        """Even-odd rule: a point is inside where a ray along +s crosses the outline an odd number of times."""
        pts = np.asarray(self.points)
        s, t = st[..., 0], st[..., 1]
        inside = np.zeros(s.shape, bool)
        for (s0, t0), (s1, t1) in zip(pts, np.roll(pts, -1, axis=0), strict=True):
            if t0 == t1:
                continue
            crosses = (t0 > t) != (t1 > t)
            s_cross = s0 + (t - t0) * (s1 - s0) / (t1 - t0)
            inside ^= crosses & (s < s_cross)
        return inside

    @property
    def area(self) -> float:
        s, t = np.asarray(self.points).T
        return float(abs(np.dot(s, np.roll(t, -1)) - np.dot(t, np.roll(s, -1))) / 2)

    def outline(self) -> np.ndarray:
        return np.asarray(self.points, float)

    def bounds(self) -> np.ndarray:
        pts = np.asarray(self.points)
        return np.array([pts.min(axis=0), pts.max(axis=0)])

    def to_dict(self) -> dict:
        return {"kind": self.kind, "points": [list(p) for p in self.points]}


@dataclass(frozen=True)
class Rectangle(Polygon):
    """A rectangle in plane coordinates from corner ``lo`` (s, t) to corner ``hi`` mm."""

    points: tuple = ()
    lo: tuple[float, float] = (0.0, 0.0)
    hi: tuple[float, float] = (0.0, 0.0)
    kind = "rectangle"

    def __init__(self, lo, hi):
        (s0, t0), (s1, t1) = np.sort(np.array([lo, hi], float), axis=0)
        object.__setattr__(self, "lo", (float(s0), float(t0)))
        object.__setattr__(self, "hi", (float(s1), float(t1)))
        super().__init__(((s0, t0), (s1, t0), (s1, t1), (s0, t1)))

    def to_dict(self) -> dict:
        return {"kind": self.kind, "lo": list(self.lo), "hi": list(self.hi)}


SHAPES = {"ellipse": Ellipse, "rectangle": Rectangle, "polygon": Polygon}


def shape_from_dict(d: dict):
    """The shape a ``to_dict`` wrote."""
    kind = d.get("kind")
    if kind == "ellipse":
        return Ellipse(tuple(d["center"]), tuple(d["radii"]))
    if kind == "rectangle":
        return Rectangle(tuple(d["lo"]), tuple(d["hi"]))
    if kind == "polygon":
        return Polygon(tuple(map(tuple, d["points"])))
    from ..errors import UnknownChoiceError

    raise UnknownChoiceError("region shape", kind, tuple(SHAPES))
