"""The tagged-colon phantom: a prepared colon holding air over a horizontal level of contrast-tagged fluid.

CT colonography in a supine patient, in Hounsfield units, on 1.25 mm voxels (head end
toward +z, front toward +y, the patient's right toward +x): the residual fluid, tagged by
an oral contrast agent (+600, varying by 10 % over a centimetre: it mixes unevenly), pools
on the dependent (posterior, -y) side of the lumen below a horizontal plane, the fluid
level; the air (-1000) above it. A sigmoid-like loop of colon (radius 19-22 mm, haustral
folds 30 % deep, a 3 mm wall of +40) runs through abdominal fat (-100), rising and sinking,
so the fluid fills a third to most of the lumen where the loop sinks and none where it rises,
and the air is a thin slab above the deepest pool. Beside it: small-bowel loops (+40 wall,
+10 content), a vertebral body (a cortex of +700 round +200 trabecular bone) behind.

The colon's lumen is the air and the fluid together: the wall is the soft tissue round
both. Every surface, the fluid level included, is a partial-volume edge blurred like a
scanner's; Gaussian noise (20 HU) is added.

``meta["truth"]``: ``colon`` (:class:`Tube`; ``mask`` the lumen, air and fluid), ``fluid``
(bool mask of the tagged fluid), ``level`` (y mm of the fluid's surface) and ``landmarks``
``start`` and ``end`` (in the air, near either end of the loop).
"""

from __future__ import annotations

import numpy as np

from ..core import Volume
from ._canvas import Canvas, VoxelGrid, coverage, ellipse_cylinder_sd
from ._colon import _folds
from ._texture import smooth_field
from ._tubes import make_path, truth_tube, tube_field

__all__ = ["tagged_colon"]

FOV = (160.0, 128.0, 160.0)  # x, y, z mm
AIR, FAT, WALL_HU, TAG, BOWEL, CONTENT = -1000.0, -100.0, 40.0, 600.0, 40.0, 10.0
CORTEX, TRABECULAR = 700.0, 200.0
WALL, FOLD_DEPTH, LEVEL = 3.0, 0.3, -12.0  # mm, fraction of the radius, y (mm) of the fluid's surface
PATH = [(-70, 12, -75), (-50, 0, -50), (-20, -20, -32), (12, -16, -8), (24, 0, 22), (4, 16, 44), (-28, 10, 54),
        (-52, 4, 62), (-80, 2, 70)]
RADIUS = [19.0, 20.0, 21.0, 22.0, 21.0, 20.0, 20.0, 19.0, 19.0]
SMALL_BOWEL = [([(60, 30, -80), (55, 20, -40), (40, 30, -10), (60, 40, 20), (50, 45, 80)], 11.0),
               ([(-20, 45, -80), (-30, 40, -50), (-55, 35, -30), (-75, 40, 10)], 10.0)]
SPINE, SPINE_R = (0.0, -58.0), 18.0


def _paint_background(cv: Canvas) -> None:
    reg = cv.grid.region()
    body = ellipse_cylinder_sd(reg, SPINE, (SPINE_R, SPINE_R), (-1e3, 1e3))
    cv.paint(reg, body, CORTEX)
    cv.paint(reg, body + 2.0, TRABECULAR)
    for pts, r in SMALL_BOWEL:
        f = tube_field(cv.grid, make_path(pts, r), cv.reach)
        if f is not None:
            cv.paint(f.region, f.sdf, BOWEL)
            cv.paint(f.region, f.sdf + np.float32(2.5), CONTENT)


def tagged_colon(size=None, *, noise: float = 20.0, seed: int = 0, blur: float = 0.5, level: float = LEVEL) -> Volume:
    """Build the tagged-colon phantom (see the module docstring); ``size`` defaults to 128 voxels along the longest
    axis (1.25 mm); ``level`` is the y (mm) of the fluid's surface."""
    grid = VoxelGrid.centred(FOV, 128 if size is None else size)
    cv = Canvas(grid, FAT, blur)
    _paint_background(cv)
    path = make_path(PATH, RADIUS)
    length = float(path.arc[-1])
    field = tube_field(grid, path, reach=WALL + cv.reach)
    reg, sdf = field.region, field.sdf
    r_at = np.interp(field.arc, path.arc, path.radius).astype(np.float32)
    fold, slope = (f.astype(np.float32) for f in _folds(field.arc, length, FOLD_DEPTH, slope=True))
    lumen = (sdf + r_at * fold) / np.sqrt(1.0 + (r_at * slope) ** 2)  # d - r (1 - fold), made a distance
    tag = TAG * (1.0 + 0.1 * smooth_field(grid, 10.0, seed + 3))[reg.slices]
    below = reg.y - np.float32(level)  # signed distance (mm) to the fluid's surface, < 0 under it
    cv.paint(reg, sdf - np.float32(WALL), WALL_HU)
    # the lumen's content: fluid under the level, air above, mixed by the level's partial-volume coverage, so a
    # voxel on the fluid-wall edge mixes fluid and wall, one on the level air and fluid
    under = coverage(below, cv.h, cv.blur * cv.h)
    cv.paint(reg, lumen, under * tag + (1.0 - under) * np.float32(AIR))

    mask = np.zeros(grid.shape, bool)
    mask[reg.slices] = lumen < 0
    fluid = np.zeros(grid.shape, bool)
    fluid[reg.slices] = (lumen < 0) & (below < 0)
    radius = path.radius * (1.0 - _folds(path.arc, length, FOLD_DEPTH))
    tube = truth_tube("colon", mask, path, grid, radius=radius)
    # start and end: centerline points above the fluid, 25 mm from either end of the loop inside the grid
    cl, rad = tube.centerline, tube.radius
    air = np.flatnonzero(cl[:, 1] - 0.5 * rad > level)
    start, end = cl[air[air >= 25][0]], cl[air[air <= len(cl) - 26][-1]]
    truth = {"colon": tube, "fluid": fluid, "level": float(level),
             "landmarks": {"start": start.tolist(), "end": end.tolist()}}
    return cv.to_volume(name="tagged_colon", noise=noise, seed=seed, meta={"truth": truth})
