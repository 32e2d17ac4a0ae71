"""The chest CT: a whole-thorax scan with contrast in the vessels, as a benchmark sees one.

The second of the whole-region scans built for speed measurements (the first is ``_abdomen``):
here most rays cross the chest wall's fat and muscle, ribs and a great deal of air-filled lung whose
vessels branch down to a few millimetres. Head end toward +z, front toward +y, the patient's right
toward +x, supine on the table; field of view 400 x 331 x 367 mm from the shoulders to the upper
abdomen. Painted back to front (``_canvas``), every surface a blurred partial-volume edge:

* outside: air and the table (``_scanparts.paint_table``);
* chest wall: skin, subcutaneous fat (-105 HU), muscle (+50) thicker in front (the pectorals) and behind;
* bone: thoracic vertebrae, ten pairs of ribs and their cartilage, the sternum, both scapulae and clavicles;
* lungs (-860, denser toward the back) with a seeded tree of pulmonary vessels (+160) from each hilum and
  the main bronchi (air in a +40 wall);
* mediastinum: fat (-95) around the heart (myocardium +60 around contrast-filled chambers +160), the aorta
  (ascending, arch, descending; +180), the pulmonary trunk (+200), the oesophagus;
* below the diaphragm: the liver's dome (+105) and the stomach's gas.

Tissue texture and scanner noise as in the abdomen (``_scanparts.finish_scan``). Deterministic for a given
size and seed. ``meta["truth"]["landmarks"]``: name -> xyz world mm.
"""

from __future__ import annotations

import numpy as np

from ..core import Volume
from ._canvas import Canvas, Region, VoxelGrid, ellipsoid_sd
from ._grain import texture_field
from ._scanparts import angle_sin, body_sd, finish_scan, paint_ribs, paint_spine, paint_table, paint_wall
from ._tubes import make_path, paint_tubes, tube_field

__all__ = ["chest"]

FOV = (400.0, 331.0, 367.0)  # x, y, z mm
MEDIASTINUM = 95.0
HEART = ((-20.0, 30.0, -20.0), (62.0, 55.0, 58.0))
HILUM = 45.0  # |x| of each lung's hilum (mm), at y = -5, z = 40
LUNG = (80.0, -10.0, 10.0), (68.0, 92.0, 175.0)  # right lung (left mirrors it), cut by the mediastinum


def _dome(reg: Region) -> np.ndarray:
    """Height (z mm) of the diaphragm: a dome at -80 mm, higher on the right, falling to the back and sides."""
    return -80.0 - 0.003 * (reg.y - 20.0) ** 2 - 0.001 * reg.x * reg.x + 15.0 * (reg.x > 0) + 0.0 * reg.z


def _lung_sd(reg: Region, sx: float) -> np.ndarray:
    """Signed distance (mm) to the lung on side ``sx`` (+1 right): an ellipsoid above the diaphragm, outside the
    mediastinum and the heart, inside the ribs."""
    c = (sx * LUNG[0][0], LUNG[0][1], LUNG[0][2])
    sd = np.maximum(ellipsoid_sd(reg, c, LUNG[1]), _dome(reg) - reg.z)
    sd = np.maximum(sd, 22.0 - sx * reg.x)
    sd = np.maximum(sd, -ellipsoid_sd(reg, HEART[0], np.add(HEART[1], 6.0)))
    return np.maximum(sd, body_sd(reg, FOV[2] / 2.0, (168.0, 168.0), (100.0, 100.0), 112.0) + 32.0)


def _tree(rng, start, direction, radius: float, length: float, depth: int, out: list) -> None:
    """A branching vessel tree: each branch splits in two at about 35 degrees, 0.8 as long and 0.75 as wide."""
    d = np.asarray(direction, float) / np.linalg.norm(direction)
    end = np.asarray(start, float) + length * d
    mid = 0.5 * (np.asarray(start) + end) + rng.normal(0.0, 0.08 * length, 3)
    out.append(make_path([start, mid, end], [radius, 0.9 * radius, 0.8 * radius], smooth=False))
    if depth == 0:
        return
    for _ in range(2):
        turn = rng.normal(0.0, 1.0, 3)
        turn -= turn.dot(d) * d
        nd = d + 0.7 * turn / max(np.linalg.norm(turn), 1e-9)
        _tree(rng, end, nd, 0.75 * radius, 0.8 * length, depth - 1, out)


def _paint_lungs(cv: Canvas, seed: int, tex: np.ndarray) -> None:
    g, m = cv.grid, cv.reach
    rng = np.random.default_rng(seed + 11)
    for sx in (-1.0, 1.0):
        c = (sx * LUNG[0][0], LUNG[0][1], LUNG[0][2])
        r = g.around(c, np.add(LUNG[1], m))
        sd = _lung_sd(r, sx)
        cv.paint(r, sd, -860.0 + 60.0 * np.clip(-r.y / 100.0, -1.0, 1.0) + 15.0 * tex[r.slices])
        paths: list = []
        hilum = (sx * HILUM, -5.0, 40.0)
        for d in ((sx, 0.2, 1.0), (sx, 0.6, 0.1), (sx, -0.6, 0.0), (sx, 0.1, -1.0), (sx, -0.4, -0.8)):
            _tree(rng, hilum, d, 7.0, 40.0, 6, paths)
        f = tube_field(g, paths, cv.reach)
        if f is not None:
            cv.paint(f.region, np.maximum(f.sdf, _lung_sd(f.region, sx) - 8.0), 160.0)
        bronchus = make_path([(0.0, -5.0, 110.0), (sx * 20.0, -5.0, 60.0), (sx * 40.0, -8.0, 35.0),
                              (sx * 70.0, -20.0, 0.0)], [9.0, 7.5, 6.0, 4.0])
        paint_tubes(cv, [bronchus], [(2.0, 40.0), (0.0, -1000.0)])


def _paint_mediastinum(cv: Canvas, tex: np.ndarray) -> None:
    g, m = cv.grid, cv.reach
    r = g.around(HEART[0], np.add(HEART[1], m))
    heart = ellipsoid_sd(r, *HEART)
    cv.paint(r, heart, 60.0 + 5.0 * tex[r.slices])
    for c, semi in (((-5.0, 25.0, -10.0), (30.0, 28.0, 35.0)), ((-45.0, 35.0, -30.0), (25.0, 22.0, 30.0)),
                    ((-10.0, 0.0, 15.0), (28.0, 20.0, 25.0))):
        cv.paint(r, np.maximum(ellipsoid_sd(r, c, semi), heart + 9.0), 160.0)
    aorta = make_path([(-5.0, 20.0, 20.0), (0.0, 30.0, 90.0), (-10.0, 5.0, 120.0), (-25.0, -30.0, 100.0),
                       (-25.0, -40.0, 30.0), (-20.0, -42.0, -100.0), (-15.0, -40.0, -190.0)], 14.0)
    trunk = make_path([(-20.0, 45.0, 10.0), (-15.0, 30.0, 60.0), (-5.0, 0.0, 70.0)], 13.0)
    paint_tubes(cv, [aorta], [(1.5, 45.0), (0.0, 180.0)])
    paint_tubes(cv, [trunk], [(0.0, 200.0)])
    paint_tubes(cv, [make_path([(28.0, 10.0, 190.0), (22.0, 10.0, 30.0)], 10.0)], [(0.0, 150.0)])  # SVC
    paint_tubes(cv, [make_path([(-5.0, -30.0, 190.0), (-8.0, -28.0, -120.0)], 8.0)], [(2.5, 45.0), (0.0, -1000.0)])


def _paint_bones(cv: Canvas) -> None:
    g, m = cv.grid, cv.reach
    paint_spine(cv, 0.0, -70.0, -1e3, 1e3)
    tops = tuple(170.0 - 32.0 * k for k in range(10))
    paint_ribs(cv, tops, tuple(60.0 - 2.0 * k for k in range(10)), (150.0, 98.0), 90.0)
    r = g.region((-18.0 - m, 66.0 - m, -60.0), (18.0 + m, 94.0 + m, 160.0))  # under the skin (y = 92 in front)
    sternum = np.maximum(np.maximum(np.abs(r.x) - 14.0, np.abs(r.y - 80.0) - 6.0), np.abs(r.z - 50.0) - 105.0)
    cv.paint(r, sternum, 700.0)
    cv.paint(r, sternum + 1.6, 250.0)
    for sx in (-1.0, 1.0):  # scapulae: plates on the back, clavicles at the top
        c = (sx * 105.0, -95.0, 90.0)
        r = g.around(c, (60.0 + m, 30.0 + m, 80.0 + m))
        plate = np.abs(ellipsoid_sd(r, (sx * 105.0, -30.0, 90.0), (60.0, 72.0, 80.0)) + 4.0) - 4.0
        plate = np.maximum(plate, r.y + 70.0)
        cv.paint(r, plate, 750.0)
        cv.paint(r, plate + 1.5, 280.0)
        paint_tubes(cv, [make_path([(sx * 15.0, 80.0, 175.0), (sx * 80.0, 60.0, 185.0), (sx * 140.0, 0.0, 180.0)],
                                   7.0)], [(0.0, 750.0), (-1.6, 280.0)])


def _paint_abdomen_top(cv: Canvas, tex: np.ndarray) -> None:
    r = cv.grid.region((-160.0, -120.0, -1e3), (160.0, 110.0, -40.0))
    if r is None:
        return
    inside = body_sd(r, FOV[2] / 2.0, (168.0, 168.0), (100.0, 100.0), 112.0) + 30.0
    liver = np.maximum(np.maximum(ellipsoid_sd(r, (50.0, 0.0, -170.0), (110.0, 95.0, 100.0)), inside),
                       r.z - _dome(r) + 3.0)
    cv.paint(r, liver, 105.0 + 8.0 * tex[r.slices])
    stomach = np.maximum(ellipsoid_sd(r, (-70.0, 30.0, -150.0), (45.0, 40.0, 55.0)), r.z - _dome(r) + 3.0)
    cv.paint(r, stomach, 60.0)
    cv.paint(r, np.maximum(stomach + 4.0, 20.0 - r.y), -1000.0)
    cv.paint(r, stomach + 4.0, np.where(r.y > 20.0, -1000.0, 15.0))


def chest(size=None, *, noise: float = 12.0, seed: int = 0, blur: float = 0.6) -> Volume:
    """Build the chest CT (see the module docstring); ``size`` defaults to (224, 202, 244) voxels (nz, ny, nx),
    1.64 mm."""
    grid = VoxelGrid.centred(FOV, (224, 202, 244) if size is None else size)
    cv = Canvas(grid, -1000.0, blur)
    coarse = texture_field(grid, 24.0, seed + 2)
    paint_table(cv)
    reg = grid.region()
    sd = body_sd(reg, FOV[2] / 2.0, (168.0, 168.0), (100.0, 100.0), 112.0)
    paint_wall(cv, sd, 12.0 + 3.0 * angle_sin(reg) + 3.0 * coarse, 14.0 + 6.0 * np.abs(angle_sin(reg)), MEDIASTINUM)
    del sd
    _paint_abdomen_top(cv, coarse)
    _paint_mediastinum(cv, coarse)
    _paint_lungs(cv, seed, coarse)
    _paint_bones(cv)
    del coarse
    fine = texture_field(grid, 5.0, seed + 3)
    landmarks = {"heart": list(HEART[0]), "right_hilum": [HILUM, -5.0, 40.0], "left_hilum": [-HILUM, -5.0, 40.0]}
    return finish_scan(cv, fine, noise=noise, seed=seed, name="chest", meta={"truth": {"landmarks": landmarks}})

