"""The aortic-arch phantom: a contrast chest CT around the arch, with the lungs a few millimetres from the aorta.

What a thoracic CT angiogram shows at the level of the arch, in Hounsfield units, on
1.5 mm voxels (head end toward +z, front toward +y, the patient's right toward +x):

* mediastinal soft tissue (+40) and fat (-90);
* the aorta filled with contrast (+330, varying by 7 % over about a centimetre: the bolus
  mixes unevenly): the ascending aorta rising on the right, the arch curving back and to the
  left over the trachea's left side, the descending aorta going down left of the spine; a
  2 mm wall (+45); the brachiocephalic, left common carotid and left subclavian arteries
  leaving the arch's top;
* the pulmonary trunk and left pulmonary artery (+260) under the arch, the superior vena cava (+160)
  to the right of the ascending aorta;
* the trachea and main bronchi (air, 2 mm wall), the oesophagus (tissue round a collapsed
  air lumen of 2 mm) behind the trachea;
* a vertebral body (a 1.5 mm cortex of +900 round trabecular bone of +230, discs of +80)
  about 5 mm behind the descending aorta;
* the lungs (-850, varying by 40 HU over a few centimetres, denser toward the back)
  filling everything else within two ellipsoids, but kept ``gap`` mm (default 4) from
  each lumen, the spine and the mediastinum's core: the arch and the descending aorta pass
  within ``gap`` mm of the left lung, the classic neighbour of the aorta; a few enhanced
  pulmonary vessels (+200) in each lung.

Every surface is a partial-volume edge blurred like a scanner's (``Canvas.paint``), and
Gaussian noise (25 HU) is added.

``meta["truth"]``: ``aorta`` (:class:`Tube`, branches included, its ``mask`` the lumen),
``landmarks`` with ``start`` (ascending aorta) and ``end`` (descending aorta), about 70 mm
apart in a straight line and 150 mm along the arch.
"""

from __future__ import annotations

import numpy as np

from ..core import Volume
from ._canvas import Canvas, VoxelGrid, ellipse_cylinder_sd, ellipsoid_sd
from ._texture import smooth_field
from ._tubes import Path, make_path, truth_tube, tube_field

__all__ = ["arch"]

FOV = (168.0, 144.0, 168.0)  # x, y, z mm
TISSUE, FAT, WALL_HU, AIR, LUNG = 40.0, -90.0, 45.0, -1000.0, -850.0
CONTRAST, PULMONARY, CAVA, LUNG_VESSEL = 330.0, 260.0, 160.0, 200.0
CORTEX, TRABECULAR, DISC = 900.0, 230.0, 80.0
WALL = 2.0  # mm, vessel and airway walls

AORTA = ([(14, 26, -90), (14, 25, -40), (12, 22, 0), (6, 14, 30), (-4, 0, 42), (-16, -16, 36), (-24, -30, 16),
          (-25, -36, -20), (-25, -37, -55), (-25, -37, -90)],
         [14.0, 14.0, 13.5, 13.0, 12.5, 12.0, 11.5, 11.0, 11.0, 11.0])
BRANCHES = {
    "brachiocephalic": ([(4, 12, 36), (12, 18, 60), (18, 20, 90)], [6.5, 6.0, 6.0]),
    "left_common_carotid": ([(-4, 2, 44), (-6, 6, 64), (-8, 8, 90)], [4.0, 4.0, 4.0]),
    "left_subclavian": ([(-14, -10, 40), (-24, -10, 62), (-34, -8, 90)], [5.0, 5.0, 5.0]),
}
PULMONARY_ARTERY = ([(-14, 40, -90), (-16, 36, -40), (-16, 26, -18), (-28, 6, -8), (-44, -8, -12), (-66, -14, -18),
                     (-90, -16, -22)], [13.0, 13.0, 12.0, 10.0, 9.0, 8.0, 7.0])
CAVA_PATH = ([(40, 16, 90), (40, 16, -90)], 9.0)
TRACHEA = ([(18, -14, 90), (16, -14, -30)], 8.0)
BRONCHI = [([(16, -14, -30), (40, -18, -60), (55, -20, -90)], [7.0, 6.0, 5.5]),
           ([(16, -14, -30), (-10, -20, -60), (-20, -22, -90)], [7.0, 6.0, 5.5])]
OESOPHAGUS = ([(4, -28, 90), (4, -28, -90)], 2.0)  # air lumen; 6 mm of tissue round it
SPINE, SPINE_R = (0.0, -52.0), 15.0
LUNGS = [((-60.0, -5.0, 0.0), (50.0, 70.0, 130.0)), ((62.0, -5.0, 0.0), (48.0, 70.0, 130.0))]
MEDIASTINUM = ((0.0, 8.0), (34.0, 44.0))  # fat, an elliptic cylinder (x, y) centre and semi-axes
CORE = ((0.0, 10.0), (14.0, 40.0))  # the lungs stay `gap` mm from this cylinder too
LUNG_VESSELS = [([(s * 55, 30, 60), (s * 62, 20, 20), (s * 70, 10, -30), (s * 75, 5, -90)], 3.0) for s in (-1, 1)] + \
    [([(s * 50, -40, 80), (s * 58, -45, 30), (s * 66, -50, -20)], 2.5) for s in (-1, 1)] + \
    [([(s * 80, 40, -10), (s * 64, 20, -40), (s * 52, -5, -70)], 2.0) for s in (-1, 1)]


def _paths(spec) -> Path:
    return make_path(*spec)


def _union_sdf(grid: VoxelGrid, fields) -> np.ndarray:
    """The smallest signed distance (mm) over tube fields, on the whole grid (+inf beyond their reach)."""
    out = np.full(grid.shape, np.inf, np.float32)
    for f in fields:
        if f is not None:
            view = out[f.region.slices]
            np.minimum(view, f.sdf, out=view)
    return out


def _paint_tube(cv: Canvas, field, lumen_value, wall: float = WALL) -> None:
    """A lumen of ``lumen_value`` (HU, scalar or a field on the whole grid) in a ``wall`` mm wall of soft tissue."""
    if field is None:
        return
    reg = field.region
    cv.paint(reg, field.sdf - np.float32(wall), WALL_HU)
    value = lumen_value[reg.slices] if np.ndim(lumen_value) else lumen_value
    cv.paint(reg, field.sdf, value)


def _paint_spine(cv: Canvas) -> np.ndarray:
    reg = cv.grid.region()
    body = ellipse_cylinder_sd(reg, SPINE, (SPINE_R, SPINE_R), (-1e3, 1e3))
    u = np.mod(reg.z + 200.0, 28.0) - 14.0  # discs every 28 mm, 7 mm thick
    disc = np.abs(u) - 3.5
    cv.paint(reg, body, CORTEX)
    cv.paint(reg, body + 1.5, TRABECULAR)
    cv.paint(reg, np.maximum(body, disc), DISC)
    return np.broadcast_to(body, cv.grid.shape)


def _paint_lungs(cv: Canvas, avoid: np.ndarray, gap: float, seed: int) -> None:
    """Lungs inside their ellipsoids, ``gap`` mm from everything in ``avoid`` (a signed distance, mm)."""
    reg = cv.grid.region()
    texture = LUNG + 40.0 * smooth_field(cv.grid, 15.0, seed + 1) - 0.5 * (reg.y + 60.0)  # denser toward the back
    outside = np.float32(gap) - avoid
    for centre, semi in LUNGS:
        cv.paint(reg, np.maximum(ellipsoid_sd(reg, centre, semi), outside), texture)
    fields = [tube_field(cv.grid, make_path(pts, r), cv.reach) for pts, r in LUNG_VESSELS]
    for f in fields:
        if f is not None:
            inside = np.maximum(f.sdf, outside[f.region.slices])
            cv.paint(f.region, inside, LUNG_VESSEL)


def arch(size=None, *, noise: float = 25.0, seed: int = 0, blur: float = 0.5, gap: float = 4.0) -> Volume:
    """Build the aortic-arch phantom (see the module docstring); ``size`` defaults to 112 voxels along the
    longest axis (1.5 mm). ``gap`` (mm, > 2.5) is how close the lungs come to each lumen."""
    if not gap > WALL + 0.5:
        raise ValueError(f"gap must exceed the {WALL:g} mm wall by 0.5 mm at least, got {gap!r}")
    grid = VoxelGrid.centred(FOV, 112 if size is None else size)
    cv = Canvas(grid, TISSUE, blur)
    reg = grid.region()
    cv.paint(reg, ellipse_cylinder_sd(reg, *MEDIASTINUM, (-1e3, 1e3)), FAT)
    spine = _paint_spine(cv)
    reach = gap + cv.reach
    trunk = _paths(AORTA)
    branches = {name: _paths(spec) for name, spec in BRANCHES.items()}
    aorta = tube_field(grid, [trunk, *branches.values()], reach)
    contrast = CONTRAST * (1.0 + 0.07 * smooth_field(grid, 8.0, seed + 2))
    pulmonary = tube_field(grid, _paths(PULMONARY_ARTERY), reach)
    cava = tube_field(grid, _paths(CAVA_PATH), reach)
    airway = tube_field(grid, [make_path(*TRACHEA, smooth=False), *(make_path(p, r) for p, r in BRONCHI)], reach)
    oesophagus = tube_field(grid, make_path(*OESOPHAGUS), reach + 6.0)
    _paint_tube(cv, pulmonary, PULMONARY)
    _paint_tube(cv, cava, CAVA)
    _paint_tube(cv, aorta, contrast)
    _paint_tube(cv, airway, AIR)
    _paint_tube(cv, oesophagus, AIR, wall=6.0)
    core = ellipse_cylinder_sd(reg, *CORE, (-1e3, 1e3))
    oes = _union_sdf(grid, [oesophagus]) - 6.0
    avoid = np.minimum.reduce([_union_sdf(grid, [aorta, pulmonary, cava, airway]), oes, spine, core])
    _paint_lungs(cv, avoid, gap, seed)

    mask = np.zeros(grid.shape, bool)
    mask[aorta.region.slices] = aorta.sdf < 0
    tube = truth_tube("aorta", mask, trunk, grid, branches=[truth_tube(n, mask, p, grid) for n, p in branches.items()])
    start = tube.centerline[int(np.argmin(np.abs(tube.centerline[:, 2] - 0.0) + 100.0 * (tube.centerline[:, 0] < 0)))]
    end = tube.centerline[int(np.argmin(np.abs(tube.centerline[:, 2] - 0.0) + 100.0 * (tube.centerline[:, 0] > 0)))]
    truth = {"aorta": tube, "landmarks": {"start": start.tolist(), "end": end.tolist()}}
    return cv.to_volume(name="arch", noise=noise, seed=seed, meta={"truth": truth})
