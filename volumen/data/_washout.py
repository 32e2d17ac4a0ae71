"""The washout phantom: a thigh's femoral artery whose contrast falls by 30 % along its length.

A CT angiogram of the thigh (run-off), in Hounsfield units, on 1.25 mm voxels (head end
toward +z, front toward +y, the patient's right toward +x), scanned while the bolus
passes: the superficial femoral artery (radius 4 mm narrowing to 3.5) enters at the top at
+380 HU and leaves at the bottom at 30 % less (+266), its contrast falling linearly along its
length and varying by 5 % over a centimetre (uneven mixing); the deep femoral artery (3 mm)
leaves it near the top and falls the same way. Beside them: the femoral vein (+140, barely
enhanced yet, 3 mm from the artery), the femur (a 5 mm cortex of +1300 round fatty marrow,
-60), 3.5 mm from the artery where they come closest, muscle (+55) with fat septa (-90),
subcutaneous fat (-100), skin (+40) and the air round the thigh.

Every surface is a partial-volume edge blurred like a scanner's; Gaussian noise (20 HU).

``meta["truth"]``: ``artery`` (:class:`Tube`, the deep femoral artery as its branch; ``mask``
the lumen), ``landmarks`` ``start`` (the artery's bright top) and ``end`` (its dim bottom).
"""

from __future__ import annotations

import numpy as np

from ..core import Volume
from ._canvas import Canvas, VoxelGrid, box_sd, ellipse_cylinder_sd
from ._texture import smooth_field
from ._tubes import make_path, truth_tube, tube_field

__all__ = ["washout"]

FOV = (110.0, 110.0, 160.0)  # x, y, z mm
AIR, SKIN, FAT, MUSCLE, SEPTUM, VEIN, CORTEX, MARROW, WALL_HU = -1000.0, 40.0, -100.0, 55.0, -90.0, 140.0, 1300.0, \
    -60.0, 60.0
TOP, FALL = 380.0, 0.30  # HU at the artery's top; fraction lost by its bottom
THIGH = ((0.0, 0.0), (55.0, 50.0))
ARTERY = ([(-12, 22, 85), (-16, 14, 30), (-12, 4, -20), (-14, -4, -85)], [4.0, 4.0, 3.8, 3.5])
DEEP = ([(-13, 20, 62), (-10, 4, 40), (-12, -12, 0), (-10, -22, -40)], [3.0, 3.0, 3.0, 3.0])
VEIN_OFFSET = np.array([-8.0, -9.0, 0.0])
FEMUR = ([(16, -8, 90), (6, -10, -90)], 14.0)
CORTEX_MM, ARTERY_WALL = 5.0, 1.0


def _paint_leg(cv: Canvas) -> None:
    reg = cv.grid.region()
    thigh = ellipse_cylinder_sd(reg, *THIGH, (-1e3, 1e3))
    cv.paint(reg, thigh, SKIN)
    cv.paint(reg, thigh + 2.0, FAT)
    cv.paint(reg, thigh + 14.0, MUSCLE)
    for x0, y0, x1, y1 in ((-40, 30, 10, 44), (-45, -30, -30, 10), (30, -40, 36, 30)):  # fat septa, 1.5 mm thick
        sheet = np.maximum(box_sd(reg, (x0, y0, -1e3), (x1, y1, 1e3)), thigh + 14.0)
        c = np.array([(x0 + x1) / 2, (y0 + y1) / 2])
        d = np.array([x1 - x0, y1 - y0]) / np.hypot(x1 - x0, y1 - y0)
        across = np.abs((reg.x - c[0]) * d[1] - (reg.y - c[1]) * d[0]) - 0.75
        cv.paint(reg, np.maximum(sheet, across), SEPTUM)
    f = tube_field(cv.grid, make_path(*FEMUR, smooth=False), cv.reach)
    cv.paint(f.region, f.sdf, CORTEX)
    cv.paint(f.region, f.sdf + np.float32(CORTEX_MM), MARROW)


def washout(size=None, *, noise: float = 20.0, seed: int = 0, blur: float = 0.5, fall: float = FALL) -> Volume:
    """Build the washout phantom (see the module docstring); ``size`` defaults to 128 voxels along z (1.25 mm);
    ``fall`` is the fraction of the contrast lost from the artery's top to its bottom (0..0.6)."""
    if not 0.0 <= fall <= 0.6:
        raise ValueError(f"fall must be within [0, 0.6], got {fall!r}")
    grid = VoxelGrid.centred(FOV, 128 if size is None else size)
    cv = Canvas(grid, AIR, blur)
    _paint_leg(cv)
    artery, deep = make_path(*ARTERY), make_path(*DEEP)
    vein = make_path(np.asarray(ARTERY[0], float) + VEIN_OFFSET, 5.0)
    f = tube_field(grid, vein, cv.reach)
    cv.paint(f.region, f.sdf, VEIN)
    mixing = 1.0 + 0.05 * smooth_field(grid, 10.0, seed + 4)
    length = float(artery.arc[-1])
    branch_at = float(artery.arc[int(np.argmin(np.linalg.norm(artery.points - deep.points[0], axis=1)))])
    fields = [(tube_field(grid, artery, 1.0 + cv.reach), 0.0), (tube_field(grid, deep, 1.0 + cv.reach), branch_at)]
    for fld, _ in fields:
        cv.paint(fld.region, fld.sdf - np.float32(ARTERY_WALL), WALL_HU)
    mask = np.zeros(grid.shape, bool)
    for fld, s0 in fields:
        value = TOP * (1.0 - fall * np.clip((s0 + fld.arc) / length, 0.0, 1.0)) * mixing[fld.region.slices]
        cv.paint(fld.region, fld.sdf, value)
        mask[fld.region.slices] |= fld.sdf < 0
    tube = truth_tube("artery", mask, artery, grid, branches=[truth_tube("deep_femoral", mask, deep, grid)])
    cl = tube.centerline
    truth = {"artery": tube, "landmarks": {"start": cl[8].tolist(), "end": cl[-9].tolist()}}
    return cv.to_volume(name="washout", noise=noise, seed=seed, meta={"truth": truth})
