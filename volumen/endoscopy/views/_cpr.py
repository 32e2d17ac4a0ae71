"""Curved planar reformation (CPR) along a centerline: straightened and stretched, with cross-sections.

Two of Kanitsar et al.'s CPRs (IEEE Visualization 2002), as 3D Slicer and
OsiriX draw them:

* **straightened**: row ``k`` is the centerline point at arc ``s_k``; column
  ``c`` samples ``P(s_k) + t_c N(s_k)``, ``N`` the rotation-minimizing normal
  of :meth:`Centerline.frames` turned by ``angle`` degrees about the tangent.
  The centerline is the image's vertical mid-line, lengths along it are true;
* **stretched**: a fixed world direction ``v`` (default: across the chord from
  start to end, the direction in which the path strays most from it); row ``k`` samples the
  line through the curve parallel to ``v``, rows spaced by the curve's arc
  length perpendicular to ``v`` (the surface swept by the curve along ``v`` is
  unrolled without distortion), and column ``c`` is the world coordinate along
  ``v``, so the vessel keeps its course and the anatomy around it its shape.

Values are trilinear samples of the data (its units); outside the scan is NaN.
:func:`cross_section` gives the plane perpendicular to the path at an arc.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

__all__ = ["CPR", "curved_reformation", "cross_section", "sample_world", "cpr_width", "WIDTH_RADII", "WIDTH_MM"]

CPR_KINDS = ("straightened", "stretched")
#: a CPR is this many of its path's median lumen radii wide: the lumen a quarter of it, the wall and the tissue
#: round it the rest (a fixed 40 mm was all lumen along a colon and a sliver along a small artery)
WIDTH_RADII = 8.0
#: ... or this wide (mm) along a path that carries no radius (a keyframe path)
WIDTH_MM = 40.0


def cpr_width(centerline) -> float:
    """The width (mm) a CPR along ``centerline`` is drawn with where none is named: :data:`WIDTH_RADII` times its
    median lumen radius, :data:`WIDTH_MM` where it has none."""
    radius = float(np.median(centerline.radius)) if len(centerline.radius) else 0.0
    return WIDTH_RADII * radius if radius > 0 else WIDTH_MM


def sample_world(volume, points) -> np.ndarray:
    """Trilinear samples of ``volume`` at world points ``(..., 3)`` mm; NaN outside the scan."""
    from scipy import ndimage

    p = np.asarray(points, float)
    ijk = volume.world_to_index(p.reshape(-1, 3))
    shape = np.array(volume.shape[::-1])
    inside = np.all((ijk >= -0.5) & (ijk <= shape - 0.5), axis=1)
    vals = ndimage.map_coordinates(np.asarray(volume.data, np.float32), ijk[:, ::-1].T, order=1, mode="nearest")
    vals = np.where(inside, vals, np.nan).astype(np.float32)
    return vals.reshape(p.shape[:-1])


@dataclass(frozen=True, eq=False)
class CPR:
    """A curved planar reformation.

    Attributes
    ----------
    values : (rows, cols) float32
        Data values (NaN outside the scan); row 0 at the path's start.
    arc : (rows,) float, mm
        The centerline's arc length at each row.
    centre : (rows,) float
        Column (fractional) of the centerline in each row.
    pixel : float, mm
        Pixel size, both directions.
    kind : {"straightened", "stretched"}
    """

    values: np.ndarray
    arc: np.ndarray
    centre: np.ndarray
    pixel: float
    kind: str

    def row_at(self, s: float) -> int:
        """The row nearest arc length ``s`` (mm)."""
        return int(np.argmin(np.abs(self.arc - s)))


def _straightened(volume, cl, width, pixel, angle):
    t, n, b = cl.frames()
    a = np.deg2rad(angle)
    e = np.cos(a) * n + np.sin(a) * b
    s = np.arange(0.0, cl.length + 1e-9, pixel)
    pts = cl.at(s)
    e_s = np.stack([np.interp(s, cl.arc, e[:, k]) for k in range(3)], axis=1)
    e_s /= np.linalg.norm(e_s, axis=1, keepdims=True)
    off = (np.arange(int(round(width / pixel)) + 1) - width / pixel / 2) * pixel
    vals = sample_world(volume, pts[:, None, :] + off[None, :, None] * e_s[:, None, :])
    return vals, s, np.full(len(s), (len(off) - 1) / 2)


def _default_direction(cl) -> np.ndarray:
    """The direction, across the chord, in which the path strays most from it (its plane of curvature), so the
    stretched CPR shows the path's course; a straight path takes the world axis least aligned with it."""
    d = cl.points[-1] - cl.points[0]
    d = d / np.linalg.norm(d) if np.linalg.norm(d) > 0 else cl.tangents[0]
    off = cl.points - cl.points[0]
    off = off - np.outer(off @ d, d)
    _, sv, vt = np.linalg.svd(off, full_matrices=False)
    v = vt[0] if sv[0] > 1e-6 else np.eye(3)[int(np.argmin(np.abs(d)))]
    v = v - np.dot(v, d) * d
    return v / np.linalg.norm(v)


def _stretched(volume, cl, width, pixel, direction):
    v = _default_direction(cl) if direction is None else np.asarray(direction, float)
    v = v / np.linalg.norm(v)
    h = cl.points @ v
    perp = cl.points - h[:, None] * v
    u = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(perp, axis=0), axis=1))])
    rows = np.arange(0.0, u[-1] + 1e-9, pixel)
    s = np.interp(rows, u, cl.arc)  # arc length of each row's curve point
    pts = cl.at(s)
    cols = np.arange(h.min() - width / 2, h.max() + width / 2 + 1e-9, pixel)
    line = pts[:, None, :] + (cols[None, :] - (pts @ v)[:, None])[..., None] * v
    return sample_world(volume, line), s, (pts @ v - cols[0]) / pixel


def curved_reformation(volume, centerline, *, kind: Literal["straightened", "stretched"] = "straightened",
                       width: float | None = None, pixel: float | None = None, angle: float = 0.0,
                       direction=None) -> CPR:
    """A CPR of ``volume`` along ``centerline``.

    Parameters
    ----------
    volume : Volume
    centerline : Centerline
    kind : {"straightened", "stretched"}
    width : float or None, mm
        Extent across the path (straightened), or margin around the curve's
        extent along ``direction`` (stretched); None: :func:`cpr_width`.
    pixel : float, mm
        Pixel size (default: the smallest voxel spacing).
    angle : float, degrees
        Straightened: rotation of the cut plane about the path, from the frames' normal.
    direction : (3,) float or None
        Stretched: the vector of interest ``v`` (world), see the module docstring.

    Returns
    -------
    CPR
    """
    if kind not in CPR_KINDS:
        raise ValueError(f"kind must be one of {', '.join(CPR_KINDS)}; got {kind!r}")
    pixel = float(min(volume.spacing)) if pixel is None else float(pixel)
    width = cpr_width(centerline) if width is None else float(width)
    if not (pixel > 0 and width > 0):
        raise ValueError(f"pixel and width must be > 0 mm, got {pixel}, {width}")
    if kind == "straightened":
        vals, s, centre = _straightened(volume, centerline, width, pixel, angle)
    else:
        vals, s, centre = _stretched(volume, centerline, width, pixel, direction)
    return CPR(vals, s, centre, pixel, kind)


def cross_section(volume, centerline, s: float, *, width: float = 40.0, pixel: float | None = None) -> np.ndarray:
    """The plane perpendicular to the path at arc ``s`` (mm): ``(n, n)`` values, rows along ``-B``, columns along
    ``N`` of the rotation-minimizing frame, the centerline at the centre."""
    pixel = float(min(volume.spacing)) if pixel is None else float(pixel)
    t, n, b = centerline.frames()
    k = int(np.argmin(np.abs(centerline.arc - s)))
    off = (np.arange(int(round(width / pixel)) + 1) - width / pixel / 2) * pixel
    p = centerline.at(s)
    grid = p + off[None, :, None] * n[k] - off[:, None, None] * b[k]
    return sample_world(volume, grid)
