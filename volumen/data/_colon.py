"""The colon of the torso phantom: an air-filled tube with a soft-tissue wall, haustral folds and one polyp.

The path is a smooth 3-D curve from the rectum (arc length 0) through the
sigmoid, the descending colon, the splenic flexure, a sagging transverse colon,
the hepatic flexure and the ascending colon to the cecum. Along it, with ``r(s)``
the nominal lumen radius at arc length ``s`` and ``d`` a voxel's distance to the
centerline:

* lumen (air, -1000 HU): ``d < r(s) * (1 - fold(s))``, where ``fold`` is a sum of
  Gaussian ridges (haustral folds) every ``FOLD_PERIOD`` mm of depth at most
  ``fold_depth`` (< 0.5, so the lumen stays at least half open);
* wall (+40 HU): up to ``WALL`` mm beyond ``r(s)`` (at least 1.3 voxels, so the air
  never touches the surrounding tissue through a face), in pericolic fat (-100 HU);
* the polyp: a sphere of soft tissue centred on the wall surface between two folds,
  so that one hemisphere protrudes into the lumen.

Every surface is a partial-volume edge (``Canvas.paint``); the lumen is painted as
the signed distance ``max(lumen, -polyp)`` (the lumen less the polyp), so the polyp
is the wall (same HU) left standing, and the masks hold the voxels whose centre is inside.
"""

from __future__ import annotations

import numpy as np

from ._canvas import Canvas, sphere_sd
from ._tubes import make_path, truth_tube, tube_field

__all__ = ["paint_colon"]

# rectum -> sigmoid -> descending -> splenic flexure -> transverse -> hepatic flexure -> ascending -> cecum
PATH = [(0, -8, -178), (0, -4, -160), (-15, 15, -148), (-40, 32, -140), (-62, 22, -125), (-80, 5, -105),
        (-86, 5, -70), (-86, 6, -35), (-80, 12, -12), (-50, 48, -28), (0, 55, -52), (50, 48, -30),
        (80, 18, -40), (85, 8, -75), (84, 8, -105), (78, 15, -128)]
RADIUS = [16, 15, 13, 13, 13, 14, 15, 15, 16, 18, 18, 18, 19, 21, 22, 24]
WALL, FAT = 3.0, 5.0  # mm
LUMEN, WALL_HU, FAT_HU, POLYP_HU = -1000.0, 40.0, -100.0, 40.0
FOLD_PERIOD, FOLD_SIGMA, FOLD_FREE = 24.0, 2.5, 30.0  # mm; no folds in the first/last FOLD_FREE mm
POLYP_NEAR = (0.0, 55.0, -52.0)  # the polyp sits in the transverse colon, nearest this point ...
POLYP_SIDE = (0.0, 0.6, 0.8)  # ... on the wall toward this direction (anterior-superior)
# POLYP_HU must equal WALL_HU: the polyp is painted as the wall that the lumen leaves standing


def _folds(arc: np.ndarray, length: float, depth: float, slope: bool = False):
    """Relative narrowing (0..depth) of the lumen by haustral folds at arc lengths ``arc`` (mm), and with
    ``slope`` its derivative along the arc (1/mm) too."""
    centres = np.arange(FOLD_FREE, length - FOLD_FREE + 1e-9, FOLD_PERIOD)
    phase = (arc - FOLD_FREE) / FOLD_PERIOD
    nearest = np.clip(np.rint(phase), 0, max(len(centres) - 1, 0))
    dist = arc - (FOLD_FREE + nearest * FOLD_PERIOD)
    inside = (arc > FOLD_FREE - 3 * FOLD_SIGMA) & (arc < length - FOLD_FREE + 3 * FOLD_SIGMA)
    fold = np.where(inside, depth * np.exp(-0.5 * (dist / FOLD_SIGMA) ** 2), 0.0)
    return (fold, -fold * dist / FOLD_SIGMA**2) if slope else fold


def paint_colon(cv: Canvas, *, fold_depth: float = 0.4, polyp_radius: float = 6.0):
    """Paint the colon on ``cv``; return ``(Tube, polyp dict)`` (world RAS+ mm, see the module docstring)."""
    if not 0.0 <= fold_depth <= 0.5:
        raise ValueError(f"fold_depth must be within [0, 0.5] (fraction of the radius), got {fold_depth!r}")
    if not 0.0 < polyp_radius <= 10.0:
        raise ValueError(f"polyp_radius must be within (0, 10] mm, got {polyp_radius!r}")
    grid = cv.grid
    path = make_path(PATH, RADIUS)
    length = float(path.arc[-1])
    wall = max(WALL, 1.3 * max(grid.spacing))
    field = tube_field(grid, path, reach=wall + FAT + cv.reach)
    reg, sdf, arc = field.region, field.sdf, field.arc
    r_at = np.interp(arc, path.arc, path.radius).astype(np.float32)
    fold_at, fold_slope = (f.astype(np.float32) for f in _folds(arc, length, fold_depth, slope=True))
    # d - r (1 - fold), made a distance: divided by its gradient's norm across the folds' flanks
    lumen = (sdf + r_at * fold_at) / np.sqrt(1.0 + (r_at * fold_slope) ** 2)

    # the polyp, between two folds in the transverse colon
    i_near = int(np.argmin(np.linalg.norm(path.points - np.asarray(POLYP_NEAR), axis=1)))
    k = np.floor((path.arc[i_near] - FOLD_FREE) / FOLD_PERIOD)
    s_p = FOLD_FREE + (k + 0.5) * FOLD_PERIOD
    c = np.array([np.interp(s_p, path.arc, path.points[:, a]) for a in range(3)])
    tangent = np.array([np.interp(s_p, path.arc, np.gradient(path.points[:, a], path.arc)) for a in range(3)])
    tangent /= np.linalg.norm(tangent)
    side = np.asarray(POLYP_SIDE, float)
    n = side - side.dot(tangent) * tangent
    n /= np.linalg.norm(n)
    r_lumen = float(np.interp(s_p, path.arc, path.radius) * (1.0 - _folds(np.array([s_p]), length, fold_depth)[0]))
    center = c + r_lumen * n
    sphere = sphere_sd(reg, center, polyp_radius)

    cv.paint(reg, sdf - np.float32(wall + FAT), FAT_HU)
    cv.paint(reg, sdf - np.float32(wall), WALL_HU)
    cv.paint(reg, np.maximum(lumen, -sphere), LUMEN)  # the polyp (POLYP_HU == WALL_HU) is the wall left standing
    full_lumen = np.zeros(grid.shape, dtype=bool)
    full_lumen[reg.slices] = lumen < 0
    polyp_mask = np.zeros(grid.shape, dtype=bool)
    polyp_mask[reg.slices] = (sphere < 0) & full_lumen[reg.slices]
    full_lumen &= ~polyp_mask

    radius = path.radius * (1.0 - _folds(path.arc, length, fold_depth))
    tube = truth_tube("colon", full_lumen, path, grid, radius=radius)
    s_first = path.arc[int(np.argmin(np.linalg.norm(path.points - tube.centerline[0], axis=1)))]
    polyp = {"center": center.tolist(), "radius": float(polyp_radius), "arc_length": float(s_p - s_first),
             "tip": (c + (r_lumen - polyp_radius) * n).tolist(), "direction": n.tolist(),
             "lumen_radius": r_lumen, "mask": polyp_mask}
    return tube, polyp
