"""The airways phantom: the trachea and three generations of bronchi in lung, behind walls one or two voxels thick.

A chest CT for virtual bronchoscopy, in Hounsfield units, on 1 mm voxels (head end toward
+z, front toward +y, the patient's right toward +x):

* the trachea (radius 8 mm, wall 2 mm) coming down from the top through the mediastinum
  (soft tissue +40) to the carina; the right and left main bronchi (5.5-6.5 mm, wall 1.5 mm);
  the lobar bronchi (4 mm, wall 1.2 mm): right upper, middle and lower, left upper and lower;
  two segmental bronchi from each lobar one (2.5-3 mm, wall 1 mm, one voxel);
* lung parenchyma (-860, varying by 40 HU over a few centimetres) all round them, so that air
  (-1000) lies inside air-like lung behind a wall that partial volume and the scanner's blur
  thin to a few hundred HU: where a region grown at the half-way threshold between air and
  wall leaks into the lung;
* a pulmonary artery (+40, unenhanced) beside each lobar bronchus, touching its wall;
* with ``fistula`` > 0: a paratracheal air pocket (a tracheal diverticulum, radius 8 mm) in
  the mediastinum right-behind the trachea, its air 2 mm from the trachea's (the tracheal
  wall between), joined to it through a neck ``fistula`` mm across (2 mm reads as a gap of
  air about one voxel wide once blurred): an air region the lumen really leaks into.

Walls, lumens and vessels are partial-volume edges blurred like a scanner's; Gaussian noise
(20 HU) is added.

``meta["truth"]``: ``airway`` (:class:`Tube`: the trachea and right bronchi as the main path,
the others as branches; ``mask`` the lumen, the pocket excluded), ``landmarks``: ``carina``,
``start`` (trachea), ``end`` (left lower lobar bronchus), ``neck`` (where the pocket's neck
meets the trachea's lumen) and ``pocket`` (its centre).
"""

from __future__ import annotations

import numpy as np

from ..core import Volume
from ._canvas import Canvas, VoxelGrid, ellipse_cylinder_sd, sphere_sd
from ._texture import smooth_field
from ._tubes import make_path, truth_tube, tube_field

__all__ = ["airways"]

FOV = (128.0, 96.0, 128.0)  # x, y, z mm
AIR, LUNG, TISSUE, VESSEL = -1000.0, -860.0, 40.0, 40.0
CARINA = (0.0, -2.0, 8.0)
# name -> (control points, radii, wall mm); the first is the main path of the truth tube
TREE = {
    "trachea_right": ([(0, 2, 70), CARINA, (20, -6, -10), (30, -12, -32), (34, -22, -56)],
                      [8.0, 8.0, 6.5, 5.0, 4.0], 1.5),
    "right_upper": ([(18, -5, -8), (38, -2, 8), (50, 0, 20)], [4.5, 4.0, 4.0], 1.2),
    "right_middle": ([(30, -12, -30), (36, 6, -42), (40, 16, -50)], [3.5, 3.5, 3.0], 1.2),
    "left_main_lower": ([CARINA, (-26, -8, -14), (-36, -16, -38), (-42, -26, -58)], [8.0, 5.5, 4.5, 4.0], 1.5),
    "left_upper": ([(-24, -7, -12), (-40, 0, 2), (-50, 4, 16)], [4.5, 4.0, 4.0], 1.2),
    "rs1": ([(50, 0, 20), (56, 8, 34)], [3.0, 2.5], 1.0),
    "rs2": ([(50, 0, 20), (60, -8, 30)], [3.0, 2.5], 1.0),
    "rs3": ([(34, -22, -56), (42, -26, -62)], [3.0, 2.5], 1.0),
    "ls1": ([(-50, 4, 16), (-54, 12, 30)], [3.0, 2.5], 1.0),
    "ls2": ([(-50, 4, 16), (-60, -4, 26)], [3.0, 2.5], 1.0),
    "ls3": ([(-42, -26, -58), (-50, -30, -62)], [3.0, 2.5], 1.0),
}
TRACHEA_WALL = 2.0  # mm; the trachea's part of the main path is thicker-walled than the bronchi
ARTERIES = [([(40, 6, 8), (52, 8, 20)], 3.5), ([(40, 0, -42), (44, 12, -50)], 3.0), ([(-42, 6, 2), (-52, 10, 16)], 3.5),
            ([(-30, -4, -38), (-36, -16, -58)], 3.5), ([(24, -2, -34), (30, -14, -56)], 3.5)]
MEDIASTINUM = ((2.0, 0.0), (26.0, 28.0))  # soft tissue round the trachea above the carina
POCKET_R = 8.0  # mm


def _pocket() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The pocket's centre, the neck's centre (on the trachea's lumen surface) and the unit direction from
    the trachea toward the pocket (mm): right-posterior of the trachea at z = 40, against its wall."""
    axis = make_path([TREE["trachea_right"][0][0], CARINA], 8.0, smooth=False)
    k = int(np.argmin(np.abs(axis.points[:, 2] - 40.0)))
    side = np.array([1.0, -1.0, 0.0]) / np.sqrt(2.0)
    neck = axis.points[k] + 8.0 * side
    return neck + (TRACHEA_WALL + POCKET_R) * side, neck, side


def _paint_tree(cv: Canvas, reach: float):
    """Walls (each generation its own thickness), then the lumens of every branch at once; returns the lumen
    mask and the paths."""
    paths = {name: make_path(pts, r, smooth=name != "trachea_right") for name, (pts, r, _) in TREE.items()}
    for name, (_, _, wall) in TREE.items():
        f = tube_field(cv.grid, paths[name], reach)
        if f is not None:
            cv.paint(f.region, f.sdf - np.float32(wall), TISSUE)
    trachea = make_path([TREE["trachea_right"][0][0], CARINA], 8.0, smooth=False)
    f = tube_field(cv.grid, trachea, reach)
    cv.paint(f.region, f.sdf - np.float32(TRACHEA_WALL), TISSUE)
    lumen = tube_field(cv.grid, list(paths.values()), reach)
    cv.paint(lumen.region, lumen.sdf, AIR)
    mask = np.zeros(cv.grid.shape, bool)
    mask[lumen.region.slices] = lumen.sdf < 0
    return mask, paths


def airways(size=None, *, noise: float = 20.0, seed: int = 0, blur: float = 0.5, fistula: float = 0.0) -> Volume:
    """Build the airways phantom (see the module docstring); ``size`` defaults to 128 voxels along the longest
    axis (1 mm). ``fistula`` (mm, 0: none) is the width of the neck joining an air pocket to the trachea."""
    if not 0.0 <= fistula <= 8.0:
        raise ValueError(f"fistula must be within [0, 8] mm, got {fistula!r}")
    grid = VoxelGrid.centred(FOV, 128 if size is None else size)
    reg = grid.region()
    texture = LUNG + 40.0 * smooth_field(grid, 12.0, seed + 1)
    cv = Canvas(grid, LUNG, blur)
    cv.data[...] = texture
    cv.paint(reg, ellipse_cylinder_sd(reg, *MEDIASTINUM, (CARINA[2] + 12.0, 1e3)), TISSUE)
    reach = 2.0 + cv.reach
    for pts, r in ARTERIES:
        f = tube_field(grid, make_path(pts, r), cv.reach)
        cv.paint(f.region, f.sdf, VESSEL)
    mask, paths = _paint_tree(cv, reach)
    pocket, neck, side = _pocket()
    if fistula > 0:
        r = grid.around(pocket, POCKET_R + 4.0 + cv.reach)
        cv.paint(r, sphere_sd(r, pocket, POCKET_R), AIR)
        seg = make_path([neck - 2.0 * side, pocket], fistula / 2.0, smooth=False)  # through the wall between
        f = tube_field(grid, seg, cv.reach)
        cv.paint(f.region, f.sdf, AIR)
    main = paths.pop("trachea_right")
    tube = truth_tube("airway", mask, main, grid, branches=[truth_tube(n, mask, p, grid) for n, p in paths.items()])
    lower = paths["left_main_lower"].points
    landmarks = {"carina": list(CARINA), "start": [0.0, 2.0, 40.0], "end": lower[-12].tolist(),
                 "neck": neck.tolist(), "pocket": pocket.tolist()}
    truth = {"airway": tube, "landmarks": landmarks}
    return cv.to_volume(name="airways", noise=noise, seed=seed, meta={"truth": truth})
