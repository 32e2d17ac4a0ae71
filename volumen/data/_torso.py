"""The torso phantom: a contrast-enhanced CT of the trunk in Hounsfield units.

Head end toward +z, front toward +y, the patient's right toward +x. Painted back
to front on a float canvas (see ``_canvas``):

* body wall: skin (+40 HU), subcutaneous fat (-100), muscle (+50), paraspinal muscles;
* abdomen (+30) with liver (+60, right, under the diaphragm), spleen (+45, left), kidneys (+35);
* thorax: lungs (-850) above a two-domed diaphragm, heart (+40, left of the midline), ribs (+600),
  sternum (+500);
* spine along z, posterior: vertebral bodies (+700) with discs (+80), arches (+800) around the
  spinal canal (+10), spinous processes;
* the aorta filled with contrast (+300) in a soft-tissue wall, left-anterior of the spine, with
  celiac, superior mesenteric, both renal and both iliac arteries;
* the airway (air): trachea entering from the top, carina, main bronchi and a lobar generation;
* the colon with haustral folds and one polyp (``_colon``).

Every surface is a partial-volume edge (``Canvas.paint``), so no surface is a voxel staircase.

``meta["truth"]``: ``landmarks`` (name -> xyz world mm), ``colon``, ``aorta``, ``airway``
(:class:`Tube`, branches on the aorta and airway) and ``polyp``.
"""

from __future__ import annotations

import numpy as np

from ..core import Volume
from ._canvas import Canvas, Region, VoxelGrid, ellipse_cylinder_sd, ellipsoid_sd
from ._colon import paint_colon
from ._tubes import make_path, paint_tubes, truth_tube

__all__ = ["torso"]

FOV = (360.0, 260.0, 400.0)  # x, y, z mm
BODY_AX = (165.0, 115.0)  # body cross-section semi-axes (x, y) mm
SKIN, SUBCUT, WALL = 2.5, 15.0, 27.0  # depths (mm) where fat, muscle and the cavity begin
SPINE = (0.0, -55.0)  # vertebral body centre (x, y)
CONTRAST, AIR, LUNG = 300.0, -1000.0, -850.0
LIVER = ((65.0, 10.0, 25.0), (80.0, 75.0, 45.0))
SPLEEN = ((-80.0, -45.0, 15.0), (28.0, 30.0, 35.0))
HEART = ((-20.0, 35.0, 65.0), (55.0, 45.0, 50.0))
RIB_ENDS = (70.0,) * 7 + (50.0, 30.0, 10.0)  # degrees: where each rib ends in front; the lowest are short
KIDNEY_C, KIDNEY_AX = (75.0, -55.0, -45.0), (25.0, 20.0, 50.0)  # right kidney; the left mirrors it

AORTA = ([(-30, -24, 215), (-27, -23, 120), (-18, -20, 40), (-10, -17, -40), (-5, -15, -115)],
         [12.0, 11.5, 10.5, 9.5, 8.5])
CARINA = (4.0, 0.0, 135.0)
TRACHEA = ([(4, 0, 215), CARINA], 9.0)
R_MAIN = [CARINA, (28, 0, 118)]
L_MAIN = [CARINA, (-40, 5, 112)]


def _diaphragm(x: np.ndarray) -> np.ndarray:
    """Height (z mm) of the diaphragm at x: a dome under each lung, the right one higher."""
    return 5.0 + 32.0 * np.exp(-(((x - 70.0) / 45.0) ** 2)) + 26.0 * np.exp(-(((x + 70.0) / 45.0) ** 2))


def _below_diaphragm_sd(reg: Region) -> np.ndarray:
    """Signed distance (mm, < 0 below) to the diaphragm's surface (height over it, divided by its slope's norm)."""
    x = reg.x.astype(np.float64)
    slope = (-32.0 * 2.0 * (x - 70.0) / 45.0**2 * np.exp(-(((x - 70.0) / 45.0) ** 2))
             - 26.0 * 2.0 * (x + 70.0) / 45.0**2 * np.exp(-(((x + 70.0) / 45.0) ** 2)))
    return ((reg.z - _diaphragm(reg.x)) / np.sqrt(1.0 + slope * slope)).astype(np.float32)


def _aorta_at(z: float) -> tuple[float, float, float]:
    pts = np.array(AORTA[0], float)[::-1]  # ascending z for interp
    return (float(np.interp(z, pts[:, 2], pts[:, 0])), float(np.interp(z, pts[:, 2], pts[:, 1])), float(z))


def _paint_body(cv: Canvas) -> None:
    reg = cv.grid.region()
    sd = ellipse_cylinder_sd(reg, (0.0, 0.0), BODY_AX, (-1e3, 1e3))
    below = _below_diaphragm_sd(reg)  # < 0 in the abdomen, > 0 in the chest
    cv.paint(reg, sd, 40.0)
    cv.paint(reg, sd + SKIN, -100.0)
    cv.paint(reg, sd + SUBCUT, 50.0)
    cv.paint(reg, np.maximum(sd + WALL, below), 30.0)
    cv.paint(reg, np.maximum(sd + WALL, -below), 40.0)
    g, m = cv.grid, cv.reach  # organs: each on its box (plus the blurred edge's reach) only
    for sx in (-1.0, 1.0):  # paraspinal muscles
        r = g.region((sx * 35.0 - 25.0 - m, -100.0 - m, -1e3), (sx * 35.0 + 25.0 + m, -60.0 + m, 1e3))
        cv.paint(r, ellipse_cylinder_sd(r, (sx * 35.0, -80.0), (25.0, 20.0), (-1e3, 1e3)), 50.0)
    r = g.around(LIVER[0], np.add(LIVER[1], m))
    cv.paint(r, np.maximum(ellipsoid_sd(r, *LIVER), _below_diaphragm_sd(r)), 60.0)
    r = g.around(SPLEEN[0], np.add(SPLEEN[1], m))
    cv.paint(r, ellipsoid_sd(r, *SPLEEN), 45.0)
    for sx in (-1.0, 1.0):
        c = (sx * KIDNEY_C[0], KIDNEY_C[1], KIDNEY_C[2])
        r = g.around(c, np.add(KIDNEY_AX, m))
        cv.paint(r, ellipsoid_sd(r, c, KIDNEY_AX), 35.0)
    for sx in (-1.0, 1.0):  # lungs: above the diaphragm, inside the ribs, beside the mediastinum
        c, semi = (sx * 72.0, -5.0, 120.0), (62.0, 82.0, 125.0)
        r = g.around(c, np.add(semi, m))
        wall = ellipse_cylinder_sd(r, (0.0, 0.0), BODY_AX, (-1e3, 1e3)) + 30.0
        lung = np.maximum(np.maximum(ellipsoid_sd(r, c, semi), -_below_diaphragm_sd(r)),
                          np.maximum(wall, 24.0 - sx * r.x))
        cv.paint(r, lung, LUNG)
    r = g.around(HEART[0], np.add(HEART[1], m))
    cv.paint(r, ellipsoid_sd(r, *HEART), 40.0)


def _disc_sd(z: np.ndarray, z0: float, period: float, thickness: float) -> np.ndarray:
    """Signed distance (mm) to the discs: slabs ``thickness`` mm thick across z, starting at ``z0 + n period``."""
    u = np.mod(z - (z0 + thickness / 2.0) + period / 2.0, period) - period / 2.0  # from the nearest disc's middle
    return np.abs(u) - thickness / 2.0


def _paint_bones(cv: Canvas) -> None:
    g = cv.grid
    reg = g.region((-20.0 - cv.reach, -104.0 - cv.reach, -1e3), (20.0 + cv.reach, -38.0 + cv.reach, 1e3))
    disc = _disc_sd(reg.z, -200.0, 32.0, 7.0)
    body = ellipse_cylinder_sd(reg, SPINE, (20.0, 17.0), (-1e3, 1e3))
    cv.paint(reg, body, 700.0)
    cv.paint(reg, np.maximum(body, disc), 80.0)
    arch = ellipse_cylinder_sd(reg, (0.0, -82.0), (12.5, 12.5), (-1e3, 1e3))
    cv.paint(reg, np.maximum(arch, -disc), 800.0)
    cv.paint(reg, np.maximum(ellipse_cylinder_sd(reg, (0.0, -97.0), (4.0, 7.0), (-1e3, 1e3)), -disc), 800.0)
    cv.paint(reg, arch + 4.5, 10.0)
    ribs = []
    for k, end in enumerate(RIB_ENDS):  # ribs: from the spine around inside the body wall, lower at the front
        theta = np.radians(np.linspace(-103.0, end, 18))  # angle around the body, 0 = patient's side
        drop = 35.0 * (theta - theta[0]) / np.radians(173.0)
        for sx in (-1.0, 1.0):
            pts = np.stack([sx * (BODY_AX[0] - 22.0) * np.cos(theta), (BODY_AX[1] - 22.0) * np.sin(theta),
                            185.0 - 18.0 * k - drop], axis=1)
            ribs.append(make_path(pts, 4.5))
    paint_tubes(cv, ribs, [(0.0, 600.0)])
    reg = g.region((-15.0 - cv.reach, 87.0 - cv.reach, 60.0 - cv.reach), (15.0 + cv.reach, 99.0 + cv.reach, 1e3))
    cv.paint(reg, ellipse_cylinder_sd(reg, (0.0, BODY_AX[1] - 22.0), (15.0, 6.0), (60.0, 1e3)), 500.0)


def _aorta(cv: Canvas, wall: float):
    trunk = make_path(*AORTA)
    celiac = make_path([_aorta_at(-5), (-16, 15, -2), (-11, 30, 5)], 4.0)
    sma = make_path([_aorta_at(-25), (-9, 8, -27), (-7, 18, -50), (-5, 20, -95)], 4.0)
    renal_l = make_path([_aorta_at(-40), (-40, -30, -43), (-62, -48, -45)], 4.0)
    renal_r = make_path([_aorta_at(-40), (20, -30, -43), (62, -48, -45)], 4.0)
    iliac_l = make_path([AORTA[0][-1], (-35, -14, -150), (-55, -5, -215)], [8.0, 7.0, 6.5])
    iliac_r = make_path([AORTA[0][-1], (30, -14, -150), (50, -5, -215)], [8.0, 7.0, 6.5])
    branches = {"celiac": celiac, "superior_mesenteric": sma, "renal_left": renal_l, "renal_right": renal_r,
                "iliac_left": iliac_l, "iliac_right": iliac_r}
    mask = paint_tubes(cv, [trunk, *branches.values()], [(wall, 40.0), (0.0, CONTRAST)])
    return trunk, branches, mask


def _airway(cv: Canvas, wall: float):
    trachea_path, r_trachea = TRACHEA
    main = make_path([*trachea_path, *R_MAIN[1:], (50, -12, 95), (62, -22, 60)], [r_trachea, r_trachea, 6.5, 5.0, 4.0],
                     smooth=False)
    branches = {
        "right_upper": make_path([R_MAIN[-1], (52, 2, 135), (65, 5, 150)], [5.0, 4.5, 4.0]),
        "left_main_lower": make_path([*L_MAIN, (-60, -12, 88), (-70, -25, 55)], [6.5, 6.0, 5.0, 4.0]),
        "left_upper": make_path([L_MAIN[-1], (-60, 5, 128), (-70, 8, 145)], [5.0, 4.5, 4.0]),
    }
    mask = paint_tubes(cv, [main, *branches.values()], [(wall, 40.0), (0.0, AIR)])
    return main, branches, mask


def torso(size=None, *, noise: float = 10.0, seed: int = 0, blur: float = 0.5, fold_depth: float = 0.4,
          polyp_radius: float = 6.0) -> Volume:
    """Build the torso phantom (see the module docstring); ``size`` defaults to 160 voxels along z (400 mm)."""
    grid = VoxelGrid.centred(FOV, 160 if size is None else size)
    cv = Canvas(grid, AIR, blur)
    _paint_body(cv)
    _paint_bones(cv)
    wall = max(3.0, 1.3 * max(grid.spacing))
    trunk, aorta_branches, aorta_mask = _aorta(cv, wall)
    air_main, air_branches, air_mask = _airway(cv, wall)
    colon, polyp = paint_colon(cv, fold_depth=fold_depth, polyp_radius=polyp_radius)
    # what painted later (the colon's fat) may cover a vessel: the masks keep what the data shows, the
    # voxels on the lumen's side of the half-way threshold between lumen and wall
    aorta_mask &= cv.data > (CONTRAST + 40.0) / 2.0
    air_mask &= cv.data < (AIR + 40.0) / 2.0

    def tree(name, mask, main, branches):
        return truth_tube(name, mask, main, grid, branches=[truth_tube(n, mask, p, grid) for n, p in branches.items()])

    landmarks = {
        "center": [0.0, 0.0, 0.0],
        "carina": list(CARINA),
        "aortic_bifurcation": [float(v) for v in AORTA[0][-1]],
        "heart": list(HEART[0]),
        "liver": list(LIVER[0]),
        "spleen": list(SPLEEN[0]),
        "right_kidney": list(KIDNEY_C),
        "left_kidney": [-KIDNEY_C[0], KIDNEY_C[1], KIDNEY_C[2]],
        "rectum": colon.centerline[0].tolist(),
        "cecum": colon.centerline[-1].tolist(),
        "polyp": polyp["center"],
    }
    truth = {"landmarks": landmarks, "colon": colon, "polyp": polyp,
             "aorta": tree("aorta", aorta_mask, trunk, aorta_branches),
             "airway": tree("airway", air_mask, air_main, air_branches)}
    return cv.to_volume(name="torso", noise=noise, seed=seed, meta={"truth": truth})
