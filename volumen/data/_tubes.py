"""Tubes: paths, their distance field on a grid, and the ``Tube`` ground truth of a phantom.

A tube is a polyline (world RAS+ mm) with a radius at every vertex. Its field on
a grid is, per voxel, the smallest ``d - r`` over the polyline's segments, where
``d`` is the distance to the segment and ``r`` the radius interpolated at the
closest point, together with the arc length of that closest point. The kernel
visits each segment's bounding box only (Numba, compiled on first use and cached on
disk), so a
metre of colon on a 2.5 mm grid costs a few tens of milliseconds.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import numpy as np

from ._canvas import Canvas, Region, VoxelGrid

__all__ = ["Tube", "TubeField", "Path", "make_path", "tube_field", "paint_tubes", "truth_tube"]


@dataclass(frozen=True, eq=False)
class Tube:
    """Ground truth of a tubular structure of a phantom.

    Attributes
    ----------
    name : str
    mask : (nz, ny, nx) bool
        The lumen ``[z, y, x]`` as painted in the data (air for the colon and airway,
        contrast for the aorta), branches included: the voxels whose centre is inside
        it, which the partial-volume edges put on the lumen's side of the half-way
        value between lumen and wall (exactly the lumen's value away from the wall).
    centerline : (N, 3) float
        World RAS+ mm, from one end to the other, one point about every millimetre.
    radius : (N,) float
        Lumen radius (mm) at each centerline point (narrowed where a fold is).
    branches : tuple of Tube
        Side branches; they share the parent's ``mask`` (the same array).
    """

    name: str
    mask: np.ndarray
    centerline: np.ndarray
    radius: np.ndarray
    branches: tuple[Tube, ...] = ()

    @property
    def arc_length(self) -> np.ndarray:
        """(N,) cumulative length (mm) along the centerline, 0 at its first point."""
        step = np.linalg.norm(np.diff(self.centerline, axis=0), axis=1)
        return np.concatenate([[0.0], np.cumsum(step)])

    @property
    def length(self) -> float:
        """Total centerline length (mm)."""
        return float(self.arc_length[-1])

    def __repr__(self) -> str:
        return (f"Tube({self.name!r}, {len(self.centerline)} points, length {self.length:.0f} mm, "
                f"radius {self.radius.min():.1f}..{self.radius.max():.1f} mm, "
                f"{int(self.mask.sum())} lumen voxels, {len(self.branches)} branches)")


@dataclass(frozen=True, eq=False)
class Path:
    """A path resampled every ``step`` mm: ``points`` (N, 3) xyz mm, ``radius`` (N,) mm, ``arc`` (N,) mm."""

    points: np.ndarray
    radius: np.ndarray
    arc: np.ndarray


def make_path(control_xyz, control_radius, *, step: float = 1.0, smooth: bool = True) -> Path:
    """Resample a path through control points (world mm) to one point every ``step`` mm of arc.

    ``smooth`` passes a cubic spline (chord-length parameter) through the control
    points; otherwise the path is the straight polyline. Radii (mm, one per control
    point) are interpolated linearly in the same parameter.
    """
    from scipy.interpolate import CubicSpline

    pts = np.asarray(control_xyz, dtype=float)
    rad = np.broadcast_to(np.asarray(control_radius, dtype=float), (len(pts),))
    chord = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))])
    u = np.linspace(0.0, chord[-1], max(int(chord[-1] / step) * 8, 16))
    if smooth and len(pts) > 2:
        dense = CubicSpline(chord, pts, axis=0, bc_type="natural")(u)
    else:
        dense = np.stack([np.interp(u, chord, pts[:, a]) for a in range(3)], axis=1)
    dense_arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(dense, axis=0), axis=1))])
    n = max(int(round(dense_arc[-1] / step)), 1) + 1
    arc = np.linspace(0.0, dense_arc[-1], n)
    u_at = np.interp(arc, dense_arc, u)
    points = np.stack([np.interp(u_at, u, dense[:, a]) for a in range(3)], axis=1)
    return Path(points, np.interp(u_at, chord, rad), arc)


@dataclass(frozen=True)
class TubeField:
    """A tube's field on a region: ``sdf`` = d - r(s) (mm, +inf beyond reach), ``arc`` = s at the closest point."""

    region: Region
    sdf: np.ndarray
    arc: np.ndarray


def tube_field(grid: VoxelGrid, path, reach: float) -> TubeField | None:
    """Field of ``path`` on the voxels of ``grid`` within ``reach`` mm outside its surface.

    ``path`` may be a sequence of paths: the field is then their union (the smallest
    ``d - r`` over all of them) on the box that holds them all. Returns None when the
    tube (plus reach) misses the grid.
    """
    paths = [path] if isinstance(path, Path) else list(path)
    lo_xyz = np.min([p.points.min(axis=0) - (float(p.radius.max()) + reach) for p in paths], axis=0)
    hi_xyz = np.max([p.points.max(axis=0) + (float(p.radius.max()) + reach) for p in paths], axis=0)
    reg = grid.region(lo_xyz, hi_xyz)
    if reg is None:
        return None
    shape = (reg.z.shape[0], reg.y.shape[1], reg.x.shape[2])
    sdf = np.full(shape, np.inf, dtype=np.float32)
    arc = np.zeros(shape, dtype=np.float32)
    lo = np.array([float(reg.x[0, 0, 0]), float(reg.y[0, 0, 0]), float(reg.z[0, 0, 0])])
    h = np.array(grid.spacing[::-1], dtype=float)
    kernel = _compiled_kernel()
    for p in paths:
        kernel(np.ascontiguousarray(p.points, np.float64), np.ascontiguousarray(p.radius, np.float64),
               np.ascontiguousarray(p.arc, np.float64), lo, h, float(reach), sdf, arc)
    return TubeField(reg, sdf, arc)


@cache
def _compiled_kernel():
    """The kernel compiled by Numba (imported here, so ``import volumen.data`` stays light); cached in the
    machine's kernel cache under this file's contents (its group in ``volumen.jit.GROUPS``)."""
    from ..jit import njit

    return njit(cache=True)(_tube_kernel)


def _tube_kernel(pts, rad, arcs, lo, h, reach, sdf, arc_out):
    """For each segment, visit its bounding box and keep the smallest d - r (and its arc length)."""
    nz, ny, nx = sdf.shape
    n_axis = (nx, ny, nz)
    for s in range(pts.shape[0] - 1):
        ax, ay, az = pts[s, 0], pts[s, 1], pts[s, 2]
        bx, by, bz = pts[s + 1, 0] - ax, pts[s + 1, 1] - ay, pts[s + 1, 2] - az
        bb = bx * bx + by * by + bz * bz
        r0, dr = rad[s], rad[s + 1] - rad[s]
        s0, ds = arcs[s], arcs[s + 1] - arcs[s]
        pad = max(rad[s], rad[s + 1]) + reach
        lo_i = np.empty(3, np.int64)
        hi_i = np.empty(3, np.int64)
        for a in range(3):
            p0 = min(pts[s, a], pts[s + 1, a]) - pad
            p1 = max(pts[s, a], pts[s + 1, a]) + pad
            lo_i[a] = max(int(np.ceil((p0 - lo[a]) / h[a])), 0)
            hi_i[a] = min(int(np.floor((p1 - lo[a]) / h[a])), n_axis[a] - 1)
        for k in range(lo_i[2], hi_i[2] + 1):
            pz = lo[2] + k * h[2] - az
            for j in range(lo_i[1], hi_i[1] + 1):
                py = lo[1] + j * h[1] - ay
                for i in range(lo_i[0], hi_i[0] + 1):
                    px = lo[0] + i * h[0] - ax
                    t = (px * bx + py * by + pz * bz) / bb if bb > 0 else 0.0
                    t = min(max(t, 0.0), 1.0)
                    qx, qy, qz = px - t * bx, py - t * by, pz - t * bz
                    v = np.sqrt(qx * qx + qy * qy + qz * qz) - (r0 + t * dr)
                    if v < sdf[k, j, i]:
                        sdf[k, j, i] = v
                        arc_out[k, j, i] = s0 + t * ds


def paint_tubes(cv: Canvas, paths, layers) -> np.ndarray:
    """Paint a tree of ``paths`` as nested partial-volume shells; return the lumen ``d - r < 0`` as a
    bool mask [z, y, x] (the voxels whose centre is inside).

    ``layers`` is a sequence of ``(offset_mm, value_HU)`` painted in order by the
    coverage of ``d - r < offset`` (see :meth:`Canvas.paint`): e.g. ``[(3.0, 40.0),
    (0.0, -1000.0)]`` is a 3 mm wall around air. Each layer is painted on the union
    of all the paths (one signed distance, the smallest over them), so a branch's wall
    never covers its parent's lumen and junctions have no seams.
    """
    mask = np.zeros(cv.grid.shape, dtype=bool)
    reach = max(max(o for o, _ in layers), 0.0) + cv.reach
    f = tube_field(cv.grid, paths, reach)
    if f is None:
        return mask
    for offset, value in layers:
        cv.paint(f.region, f.sdf - np.float32(offset), value)
    mask[f.region.slices] = f.sdf < 0
    return mask


def truth_tube(name: str, mask: np.ndarray, path: Path, grid: VoxelGrid, radius=None, branches=()) -> Tube:
    """The :class:`Tube` of a painted path: its centerline kept to the longest run of points
    inside the grid's voxel-centre box, with ``radius`` (default ``path.radius``) on those points."""
    radius = path.radius if radius is None else np.asarray(radius, float)
    lo = np.asarray(grid.origin)
    hi = lo + (np.array(grid.shape[::-1]) - 1) * np.array(grid.spacing[::-1])
    inside = np.all((path.points >= lo) & (path.points <= hi), axis=1)
    # longest run of consecutive True
    edges = np.flatnonzero(np.diff(np.concatenate([[0], inside.astype(np.int8), [0]])))
    starts, stops = edges[::2], edges[1::2]
    if starts.size == 0:
        raise ValueError(f"tube {name!r} lies outside the grid")
    best = int(np.argmax(stops - starts))
    keep = slice(starts[best], stops[best])
    return Tube(name, mask, np.ascontiguousarray(path.points[keep]), np.ascontiguousarray(radius[keep]),
                tuple(branches))
