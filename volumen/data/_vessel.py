"""The stenosis phantom: a curved contrast-filled artery with a 50 % stenosis and a fusiform aneurysm.

What a CT angiogram shows of a diseased artery, in Hounsfield units, on 1 mm voxels (head end toward +z,
front toward +y, the patient's right toward +x), made to check the numbers read off a vessel:

* an artery curving through space (no plane holds it) about 220 mm long, radius 5 mm, filled with
  contrast whose value falls along the path from 460 to 260 HU (the bolus washing out downstream),
  varies by 7 % over about a centimetre (uneven mixing) and is ``layering`` HU brighter at the back than
  at the front (contrast settling toward the patient's back), in a 1.5 mm wall (+45);
* a stenosis a third of the way along: the radius narrows smoothly (a raised cosine 16 mm long) to half,
  a 50 % diameter reduction; a fusiform aneurysm two thirds of the way along: the radius widens
  smoothly (30 mm long) to 9 mm, a maximum diameter of 18 mm;
* soft tissue (+40, varying by 10 HU over a few centimetres) all round.

Every surface is a partial-volume edge blurred like a scanner's, and Gaussian noise (20 HU) is added.

``meta["truth"]``: ``vessel`` (:class:`Tube`: its centerline every half millimetre and the radius of its
section orthogonal to the path there, :func:`section_radius`: the analytic values every cross-section
measure is checked against), ``ball_radius`` (mm, per centerline point: the radius of the largest ball
centred there that fits, the maximum inscribed sphere's), ``stenosis`` (per cent diameter reduction, 50),
``max_diameter`` (mm, 18), ``landmarks``: ``start`` and ``end`` (on the centerline 6 mm from its ends),
``stenosis`` and ``aneurysm`` (the narrowest and widest centerline points).
"""

from __future__ import annotations

import numpy as np

from ..core import Volume
from ._canvas import Canvas, VoxelGrid
from ._texture import smooth_field
from ._tubes import Path, make_path, truth_tube, tube_field

__all__ = ["stenosis_phantom", "radius_profile", "section_radius"]

FOV = (96.0, 96.0, 176.0)  # x, y, z mm
TISSUE, WALL_HU = 40.0, 45.0
CONTRAST = (460.0, 260.0)  # HU at the path's start and end
WALL = 1.5  # mm
RADIUS = 5.0  # mm, the healthy artery
PATH = [(-20, -18, -80), (-6, 6, -50), (18, 14, -20), (24, -8, 12), (4, -22, 40), (-16, -6, 66), (-22, 14, 80)]
#: (fraction of the path's length at the centre, length mm, relative change of the radius at the centre)
STENOSIS = (0.33, 16.0, -0.5)
ANEURYSM = (0.68, 30.0, 0.8)
END_MARGIN = 6.0  # mm, the landmarks' distance from the path's ends


def _bump(arc: np.ndarray, centre: float, length: float) -> np.ndarray:
    """A raised cosine of the arc length: 1 at ``centre``, 0 from ``length / 2`` away."""
    u = np.clip(np.abs(arc - centre) / (length / 2.0), 0.0, 1.0)
    return 0.5 * (1.0 + np.cos(np.pi * u))


def radius_profile(arc: np.ndarray, length: float) -> np.ndarray:
    """The artery's radius (mm) at arc lengths ``arc`` (mm) along a path ``length`` mm long."""
    r = np.full(np.shape(arc), RADIUS)
    for where, span, change in (STENOSIS, ANEURYSM):
        r = r * (1.0 + change * _bump(np.asarray(arc, float), where * length, span))
    return r


def section_radius(path: Path, angles: int = 36, steps: int = 24) -> np.ndarray:
    """The equivalent radius (mm) of the tube's section orthogonal to its path at each point: the radius of the
    disc of the same area. The tube is the envelope of balls of radius ``r(s)`` along the path
    (:func:`._tubes.tube_field`); where ``r`` changes along it, or the path bends, its orthogonal section is no
    circle of radius ``r`` (10 % wider where the aneurysm widens fastest). Solved here without voxels: along
    ``angles`` directions in the plane, the distance ``rho`` at which the nearest ball's surface is reached
    (``steps`` bisections of ``min_s' |X(rho) - P(s')| - r(s') = 0`` over the balls within two and a half
    of the largest radii along the path), the area ``1/2 sum rho^2 dtheta``."""
    pts, rad, arc = path.points, path.radius, path.arc
    tangent = np.gradient(pts, arc, axis=0)
    tangent /= np.linalg.norm(tangent, axis=1, keepdims=True)
    normal = np.cross(tangent, np.where(np.abs(tangent[:, 2:]) < 0.9, [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]))
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    binormal = np.cross(tangent, normal)
    theta = np.linspace(0.0, 2.0 * np.pi, angles, endpoint=False)
    direction = np.cos(theta)[None, :, None] * normal[:, None] + np.sin(theta)[None, :, None] * binormal[:, None]
    reach = int(np.ceil(2.5 * rad.max() / float(np.median(np.diff(arc)))))
    near = np.clip(np.arange(len(pts))[:, None] + np.arange(-reach, reach + 1)[None], 0, len(pts) - 1)
    centres, radii = pts[near][:, None], rad[near][:, None]  # (P, 1, K, 3), (P, 1, K)
    lo, hi = np.zeros((len(pts), angles)), np.full((len(pts), angles), 2.0 * rad.max())
    for _ in range(steps):
        mid = 0.5 * (lo + hi)
        x = pts[:, None] + mid[..., None] * direction  # (P, A, 3)
        inside = np.min(np.linalg.norm(x[:, :, None] - centres, axis=-1) - radii, axis=-1) < 0
        lo, hi = np.where(inside, mid, lo), np.where(inside, hi, mid)
    return np.sqrt(np.mean(lo ** 2, axis=1))


def _path() -> Path:
    base = make_path(PATH, RADIUS, step=0.5)
    return Path(base.points, radius_profile(base.arc, float(base.arc[-1])), base.arc)


def _contrast(grid: VoxelGrid, field, path: Path, seed: int, layering: float) -> np.ndarray:
    """The lumen's value on the field's region: falling along the arc, uneven, brighter toward the back."""
    reg = field.region
    along = CONTRAST[0] + (CONTRAST[1] - CONTRAST[0]) * field.arc / float(path.arc[-1])
    mixing = 1.0 + 0.07 * smooth_field(grid, 8.0, seed + 2)[reg.slices]
    centre_y = np.interp(field.arc, path.arc, path.points[:, 1])
    radius = np.interp(field.arc, path.arc, path.radius)
    behind = np.clip((centre_y - reg.y) / (2.0 * radius), -0.5, 0.5)  # -0.5 at the front, 0.5 at the back
    return (along * mixing + layering * behind).astype(np.float32)


def stenosis_phantom(size=None, *, noise: float = 20.0, seed: int = 0, blur: float = 0.5,
                     layering: float = 60.0) -> Volume:
    """Build the stenosis phantom (see the module docstring); ``size`` defaults to 176 voxels along the longest
    axis (1 mm). ``layering`` (HU) is how much brighter the contrast is at the lumen's back than at its front."""
    if not 0.0 <= layering <= 200.0:
        raise ValueError(f"layering must be within [0, 200] HU, got {layering!r}")
    grid = VoxelGrid.centred(FOV, 176 if size is None else size)
    cv = Canvas(grid, TISSUE, blur)
    cv.data[...] += 10.0 * smooth_field(grid, 12.0, seed + 1)
    path = _path()
    field = tube_field(grid, path, WALL + cv.reach)
    cv.paint(field.region, field.sdf - np.float32(WALL), WALL_HU)
    cv.paint(field.region, field.sdf, _contrast(grid, field, path, seed, layering))
    mask = np.zeros(grid.shape, bool)
    mask[field.region.slices] = field.sdf < 0
    tube = truth_tube("vessel", mask, path, grid, radius=section_radius(path))
    arc = tube.arc_length
    landmarks = {"start": tube.centerline[int(np.searchsorted(arc, END_MARGIN))].tolist(),
                 "end": tube.centerline[int(np.searchsorted(arc, arc[-1] - END_MARGIN))].tolist(),
                 "stenosis": tube.centerline[int(np.argmin(tube.radius))].tolist(),
                 "aneurysm": tube.centerline[int(np.argmax(tube.radius))].tolist()}
    truth = {"vessel": tube, "ball_radius": truth_tube("ball", mask, path, grid).radius,
             "stenosis": 100.0 * -STENOSIS[2], "max_diameter": 2.0 * RADIUS * (1.0 + ANEURYSM[2]),
             "landmarks": landmarks}
    return cv.to_volume(name="stenosis", noise=noise, seed=seed, meta={"truth": truth})
