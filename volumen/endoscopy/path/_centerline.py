"""Centerlines: the minimal path through a lumen, kept away from the wall, smoothed and resampled.

Method (:func:`compute_centerline`):

1. ``dist`` = Euclidean distance (mm, anisotropic spacing) from each lumen
   voxel centre to the nearest voxel centre outside the lumen
   (``scipy.ndimage.distance_transform_edt``), on the lumen's bounding box;
2. end points: given (nearest lumen voxel), or the two ends of the lumen by
   two passes of geodesic farthest point (unit cost inside the lumen,
   ``skimage.graph.MCP_Geometric``): the lumen voxel farthest from the start
   (or from the deepest voxel), then the one farthest from that;
3. the path of least cost ``integral (eps + dist) ** -power ds`` between them
   (``MCP_Geometric`` on 26-connected voxels, step lengths in mm);
4. ends found automatically sit at the tips of the lumen's end caps; each is
   moved to its cap's centre: of the lumen voxels whose inscribed ball
   (radius ``dist``) reaches within one voxel of the tip, the one with the
   largest ball;
5. smoothed by a Gaussian of ``smoothing`` mm along the arc (point-reflected at
   the ends, so straight ends stay straight), passed through a cubic spline,
   resampled every ``step`` mm; the local radius is the distance field at
   each point less half a voxel (the wall lies half-way between voxel centres).
"""

from __future__ import annotations

import json
from dataclasses import dataclass

import numpy as np

from ..lumen._find import as_lumen, nearest_voxel

__all__ = ["Centerline", "compute_centerline", "resample_polyline"]


def resample_polyline(points, step: float) -> tuple[np.ndarray, np.ndarray]:
    """Points (N, 3) every ``step`` mm of arc along a polyline (linear), the last one at its end
    (a shorter last interval); returns ``(points, arc)``."""
    p = np.asarray(points, float)
    seg = np.linalg.norm(np.diff(p, axis=0), axis=1)
    arc = np.concatenate([[0.0], np.cumsum(seg)])
    keep = np.concatenate([[True], seg > 1e-12])
    p, arc = p[keep], arc[keep]
    s = np.arange(0.0, arc[-1] + 1e-9 * step, step)
    if arc[-1] - s[-1] > 1e-6 * step:
        s = np.append(s, arc[-1])
    return np.stack([np.interp(s, arc, p[:, a]) for a in range(3)], axis=1), s


@dataclass(frozen=True, eq=False)
class Centerline:
    """A path through a lumen in world RAS+ mm.

    Attributes
    ----------
    points : (N, 3) float, mm
        From the start to the end, equally spaced along the arc.
    radius : (N,) float, mm
        Local lumen radius (distance to the nearest wall) at each point.
    arc : (N,) float, mm
        Arc length from the first point.
    """

    points: np.ndarray
    radius: np.ndarray
    arc: np.ndarray

    def __post_init__(self):
        p = np.ascontiguousarray(self.points, np.float64)
        if p.ndim != 2 or p.shape[1] != 3 or len(p) < 2:
            raise ValueError(f"points must be (N >= 2, 3) mm, got shape {p.shape}")
        object.__setattr__(self, "points", p)
        object.__setattr__(self, "radius", np.ascontiguousarray(self.radius, np.float64).reshape(len(p)))
        object.__setattr__(self, "arc", np.ascontiguousarray(self.arc, np.float64).reshape(len(p)))

    @property
    def length(self) -> float:
        """Total arc length, mm."""
        return float(self.arc[-1])

    @property
    def tangents(self) -> np.ndarray:
        """(N, 3) unit tangents (derivative of the points along the arc)."""
        t = np.gradient(self.points, self.arc, axis=0)
        return t / np.linalg.norm(t, axis=1, keepdims=True)

    def at(self, s) -> np.ndarray:
        """Point(s) at arc length ``s`` (mm, clipped to [0, length]), (..., 3)."""
        s = np.clip(np.asarray(s, float), 0.0, self.length)
        return np.stack([np.interp(s, self.arc, self.points[:, a]) for a in range(3)], axis=-1)

    def tangent_at(self, s) -> np.ndarray:
        """Unit tangent(s) at arc length ``s`` (mm), (..., 3)."""
        t = self.tangents
        s = np.clip(np.asarray(s, float), 0.0, self.length)
        v = np.stack([np.interp(s, self.arc, t[:, a]) for a in range(3)], axis=-1)
        return v / np.linalg.norm(v, axis=-1, keepdims=True)

    def radius_at(self, s) -> np.ndarray:
        """Lumen radius (mm) at arc length ``s`` (mm)."""
        return np.interp(np.clip(np.asarray(s, float), 0.0, self.length), self.arc, self.radius)

    def project(self, point) -> tuple[float, float]:
        """``(arc, distance)``: arc length (mm) of the polyline's closest point to ``point``, and the distance (mm)."""
        p = np.asarray(point, float)
        a, b = self.points[:-1], self.points[1:]
        ab = b - a
        t = np.clip(np.einsum("ij,ij->i", p - a, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300), 0, 1)
        d = np.linalg.norm(a + t[:, None] * ab - p, axis=1)
        k = int(np.argmin(d))
        return float(self.arc[k] + t[k] * (self.arc[k + 1] - self.arc[k])), float(d[k])

    def frames(self, normal=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Rotation-minimizing frames along the path (double reflection, Wang et al. 2008).

        Parameters
        ----------
        normal : (3,) float or None
            First normal (made orthogonal to the first tangent); default: the
            world axis least aligned with the first tangent, orthogonalized.

        Returns
        -------
        tangent, normal, binormal : each (N, 3) unit vectors, ``binormal = tangent x normal``.
        The normal turns as little as possible around the tangent, so angles
        measured from it do not twist along the path.
        """
        t = self.tangents
        if normal is None:
            normal = np.eye(3)[int(np.argmin(np.abs(t[0])))]
        r = np.asarray(normal, float) - np.dot(normal, t[0]) * t[0]
        if np.linalg.norm(r) < 1e-9:
            raise ValueError("normal is parallel to the first tangent")
        r = r / np.linalg.norm(r)
        nrm = np.empty_like(t)
        nrm[0] = r
        p = self.points
        for i in range(len(p) - 1):
            v1 = p[i + 1] - p[i]
            c1 = np.dot(v1, v1)
            if c1 < 1e-24:
                nrm[i + 1] = r
                continue
            rl = r - (2.0 / c1) * np.dot(v1, r) * v1
            tl = t[i] - (2.0 / c1) * np.dot(v1, t[i]) * v1
            v2 = t[i + 1] - tl
            c2 = np.dot(v2, v2)
            r = rl - (2.0 / c2) * np.dot(v2, rl) * v2 if c2 > 1e-24 else rl
            r = r - np.dot(r, t[i + 1]) * t[i + 1]
            r = r / np.linalg.norm(r)
            nrm[i + 1] = r
        return t, nrm, np.cross(t, nrm)

    def reversed(self) -> Centerline:
        """The same path from its end to its start."""
        return Centerline(self.points[::-1].copy(), self.radius[::-1].copy(), self.length - self.arc[::-1])

    def to_dict(self) -> dict:
        """JSON-ready dict: ``points`` (list of [x, y, z] mm), ``radius`` (mm), ``arc`` (mm)."""
        return {"points": self.points.tolist(), "radius": self.radius.tolist(), "arc": self.arc.tolist()}

    @classmethod
    def from_dict(cls, d: dict) -> Centerline:
        extra = set(d) - {"points", "radius", "arc"}
        if extra:
            raise ValueError(f"unknown Centerline fields {sorted(extra)}; valid: ['arc', 'points', 'radius']")
        return cls(np.array(d["points"], float), np.array(d["radius"], float), np.array(d["arc"], float))

    def to_json(self) -> str:
        return json.dumps(self.to_dict())

    @classmethod
    def from_json(cls, text: str) -> Centerline:
        return cls.from_dict(json.loads(text))


def _farthest(mcp_cls, unit_cost, start, spacing) -> tuple[tuple[int, int, int], np.ndarray]:
    cum, _ = mcp_cls(unit_cost, fully_connected=True, sampling=tuple(float(s) for s in spacing)).find_costs([start])
    cum = np.where(np.isfinite(cum), cum, -1.0)
    return tuple(int(v) for v in np.unravel_index(int(np.argmax(cum)), cum.shape)), cum


def _smooth(points: np.ndarray, sigma: float, spacing: float) -> np.ndarray:
    """Gaussian smoothing (sigma in mm) of points ``spacing`` mm apart, point-reflected at both ends."""
    from scipy.ndimage import gaussian_filter1d

    s = sigma / spacing
    if s <= 0 or len(points) < 3:
        return points
    pad = min(int(np.ceil(4 * s)), len(points) - 1)
    head = 2 * points[0] - points[pad:0:-1]
    tail = 2 * points[-1] - points[-2:-pad - 2:-1]
    ext = np.concatenate([head, points, tail])
    return gaussian_filter1d(ext, s, axis=0, mode="nearest")[pad:pad + len(points)]


def _cap_centre(dist: np.ndarray, tip, spacing: np.ndarray, tol: float) -> tuple[int, int, int]:
    """The centre of the lumen's end cap at voxel ``tip``: among lumen voxels whose inscribed ball
    (radius ``dist``) reaches within ``tol`` mm of the tip, the one with the largest ball."""
    zyx = np.argwhere(dist > 0)
    r = dist[tuple(zyx.T)]
    d = np.linalg.norm((zyx - np.asarray(tip)) * spacing, axis=1)
    cand = np.flatnonzero(d <= r + tol)
    best = cand[np.lexsort((d[cand] - r[cand], -r[cand]))[0]]
    return tuple(int(v) for v in zyx[best])


def compute_centerline(volume, lumen, start=None, end=None, *, step: float = 1.0, power: float = 2.0,
                       eps: float = 0.1, smoothing: float = 4.0) -> Centerline:
    """The centerline of a lumen between two points, or between its two ends.

    Parameters
    ----------
    volume : Volume
        Geometry (affine, spacing) of the mask.
    lumen : (nz, ny, nx) bool
        The lumen ``[z, y, x]`` (:func:`lumen_mask`, or any mask).
    start, end : (3,) float, world RAS+ mm, or None
        End points (snapped to the nearest lumen voxel). None: found by
        geodesic farthest point (see the module docstring); such ends are
        trimmed at the lumen's end caps.
    step : float, mm
        Spacing of the output points along the arc.
    power : float
        Exponent ``p`` of the cost ``(eps + dist) ** -p`` (higher: more central).
    eps : float, mm
    smoothing : float, mm
        Gaussian sigma along the arc (0: no smoothing).

    Returns
    -------
    Centerline
    """
    from scipy import ndimage
    from scipy.interpolate import CubicSpline
    from skimage.graph import MCP_Geometric

    mask = as_lumen(volume, lumen)
    if not step > 0:
        raise ValueError(f"step must be > 0 mm, got {step}")
    zyx = np.argwhere(mask)
    lo = np.maximum(zyx.min(axis=0) - 1, 0)
    hi = np.minimum(zyx.max(axis=0) + 2, mask.shape)
    sub = mask[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]]
    spacing = np.array(volume.spacing, float)  # dz, dy, dx, the array order
    dist = ndimage.distance_transform_edt(sub, sampling=tuple(float(s) for s in spacing))
    unit = np.where(sub, 1.0, np.inf)

    def local(point):
        return tuple(int(v) for v in np.subtract(nearest_voxel(volume, mask, point), lo))

    a = local(start) if start is not None else None
    b = local(end) if end is not None else None
    if a is None:
        seed = b if b is not None else tuple(int(v) for v in np.unravel_index(int(np.argmax(dist)), dist.shape))
        a, _ = _farthest(MCP_Geometric, unit, seed, spacing)
    if b is None:
        b, cum = _farthest(MCP_Geometric, unit, a, spacing)
        if cum[b] <= 0:
            raise ValueError("the lumen is a single voxel: no centerline")
    tol = spacing.max()
    if start is None:
        a = _cap_centre(dist, a, spacing, tol)
    if end is None:
        b = _cap_centre(dist, b, spacing, tol)
    cost = np.where(sub, (eps + dist) ** (-float(power)), np.inf)
    mcp = MCP_Geometric(cost, fully_connected=True, sampling=tuple(float(s) for s in spacing))
    cum, _ = mcp.find_costs([a], [b])
    if not np.isfinite(cum[b]):
        raise ValueError("start and end are not connected through the lumen")
    idx = np.array(mcp.traceback(b), float) + lo  # (n, 3) z, y, x
    path = volume.index_to_world(idx[:, ::-1])
    if len(path) < 2:
        raise ValueError("start and end fall on the same lumen voxel: no centerline")
    dense_step = 0.25 * spacing.min()
    dense, _ = resample_polyline(path, dense_step)
    dense = _smooth(dense, smoothing, dense_step)
    chord = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(dense, axis=0), axis=1))])
    keep = np.concatenate([[True], np.diff(chord) > 1e-9])
    spline = CubicSpline(chord[keep], dense[keep], axis=0)
    fine_u = np.linspace(0.0, chord[-1], max(4 * len(dense), 16))
    fine = spline(fine_u)
    points, arc = resample_polyline(fine, step)
    ijk = volume.world_to_index(points) - lo[::-1]
    radius = ndimage.map_coordinates(dist, ijk[:, ::-1].T, order=1, mode="nearest") - 0.5 * spacing.min()
    return Centerline(points, np.maximum(radius, 0.0), arc)
