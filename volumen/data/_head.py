"""The head phantom: a CT of an upright head in Hounsfield units, face toward +y (anterior).

Anatomy, painted back to front on a float canvas (see ``_canvas``):

* scalp: skin (+40 HU) over subcutaneous fat (-100), soft tissue (+45) in the face and neck;
* skull (outer and inner tables +1700, each 30 % of the thickness, diploe +1050) of varying
  thickness: ~3 mm at the temples, ~6.5 mm at the vertex, ~9.5 mm at the back, ~10 mm at the base;
  a floor rising toward the front leaves room for the face below; two frontal sinuses (air in bone) in the forehead;
* a thin layer of CSF (+8), grey (+40) and white matter (+27), a third ventricle and two
  C-shaped lateral ventricles (+5) that read as a butterfly on coronal slices;
* two eyes (vitreous +10 in a +45 sclera, lens +80) in fat-filled bony orbits, a nose,
  two ears, maxillary sinuses (air in bone), a hard palate, a mandible, cervical spine;
* the nasal airway (air) from the nostrils through the nasopharynx down the pharynx;
* one dense bead (+2000 HU, radius 3 mm) on the skin on the patient's RIGHT (+x) at
  eye level, like a radiographer's "R" marker: a mirrored rendering shows it on the left.

Every surface is a partial-volume edge (``Canvas.paint``), so no surface is a voxel staircase.

``meta["truth"]`` has ``landmarks`` (name -> xyz world mm) and ``nasal_airway`` (a Tube).
"""

from __future__ import annotations

import numpy as np

from ..core import Volume
from ._canvas import (
    Canvas,
    Region,
    VoxelGrid,
    box_sd,
    ellipse_cylinder_sd,
    ellipsoid_sd,
    ellipsoid_support,
    smooth_union,
    sphere_sd,
    surface_point,
)
from ._tubes import make_path, paint_tubes, truth_tube

__all__ = ["head"]

FOV = (190.0, 230.0, 240.0)  # x, y, z mm
SKULL_C, SKULL_AX = (0.0, -10.0, 25.0), (70.0, 90.0, 78.0)  # outer table of the braincase
SCALP = 6.0  # mm of skin and fat over the skull
FACE_C, FACE_AX = (0.0, 25.0, -50.0), (52.0, 58.0, 52.0)
NOSE_C, NOSE_AX = (0.0, 84.0, -18.0), (11.0, 27.0, 9.0)  # along x, down-forward, forward-up
NOSE_ROT = np.array([[1.0, 0.0, 0.0], [0.0, 0.45, 0.893], [0.0, -0.893, 0.45]])  # columns: the nose's axes
EYE_Y, EYE_X, EYE_R = 58.0, 32.0, 12.0
MARKER_R, MARKER_Y, MARKER_HU = 3.0, 30.0, 2000.0
GREY, WHITE, BRAIN, CSF, VENTRICLE = 40.0, 27.0, 35.0, 8.0, 5.0
TABLE_HU, DIPLOE_HU, TABLE_FRACTION = 1700.0, 1050.0, 0.3


def _body_sd(reg: Region) -> np.ndarray:
    """Signed distance (mm) to the skin: union of scalp, face, nose, neck and ears."""
    sd = ellipsoid_sd(reg, SKULL_C, np.add(SKULL_AX, SCALP))
    sd = np.minimum(sd, ellipsoid_sd(reg, FACE_C, FACE_AX))
    sd = smooth_union(sd, ellipsoid_sd(reg, NOSE_C, NOSE_AX, NOSE_ROT), 6.0)
    sd = np.minimum(sd, ellipse_cylinder_sd(reg, (0.0, -8.0), (52.0, 54.0), (-200.0, -40.0)))
    for sx in (-1.0, 1.0):
        sd = np.minimum(sd, ellipsoid_sd(reg, (sx * 76.0, -8.0, 0.0), (7.0, 14.0, 24.0)))  # ear
        sd = smooth_union(sd, ellipsoid_sd(reg, (sx * 12.0, 84.0, -36.0), (7.0, 7.0, 6.0)), 6.0)  # ala of the nose
    return sd


def _skull_sd(reg: Region) -> np.ndarray:
    """Signed distance to the skull's outer surface: the braincase ellipsoid above a floor rising anteriorly."""
    t = np.clip((reg.y + 10.0) / 50.0, 0.0, 1.0)
    floor = -50.0 + 62.0 * t * t * (3.0 - 2.0 * t)  # smoothstep: posterior fossa low, anterior fossa high
    slope = (62.0 * 6.0 / 50.0) * t * (1.0 - t)  # d floor / dy: the height over the floor, made a distance
    return np.maximum(ellipsoid_sd(reg, SKULL_C, SKULL_AX), (floor - reg.z) / np.sqrt(1.0 + slope * slope))


def _skull_thickness(reg: Region) -> np.ndarray:
    """Skull thickness (mm) by direction from the braincase centre: thick at the back and base, thin at the temples."""
    ux, uy, uz = ((c - o) / a for c, o, a in zip((reg.x, reg.y, reg.z), SKULL_C, SKULL_AX, strict=True))
    norm = np.maximum(np.sqrt(ux * ux + uy * uy + uz * uz), 1e-6)
    ux, uy, uz = ux / norm, uy / norm, uz / norm
    return 6.5 + 3.0 * np.maximum(-uy, 0) ** 2 + 3.5 * np.maximum(-uz, 0) ** 2 - 3.5 * ux**4


def _paint_skull_and_brain(cv: Canvas, grey_white: bool) -> None:
    reg = cv.grid.around(SKULL_C, np.add(SKULL_AX, cv.reach))  # the braincase's box
    sd = _skull_sd(reg)
    t = _skull_thickness(reg)
    # the shell 0 > sd > -t: a dense outer and inner table (TABLE_HU), each TABLE_FRACTION of the
    # thickness, around the softer diploe; constant layers, so every edge is a smooth partial volume
    cv.paint(reg, sd, TABLE_HU)
    cv.paint(reg, sd + TABLE_FRACTION * t, DIPLOE_HU)
    cv.paint(reg, sd + (1.0 - TABLE_FRACTION) * t, TABLE_HU)
    cv.paint(reg, sd + t, CSF)  # the inner surface
    inner = sd + t + 2.0  # signed distance to the brain surface
    if grey_white:
        cv.paint(reg, inner, GREY)
        cv.paint(reg, inner + 3.5, WHITE)
    else:
        cv.paint(reg, inner, BRAIN)
    r3 = cv.grid.around((0.0, -5.0, 20.0), np.add((2.5, 14.0, 8.0), cv.reach))
    if r3 is not None:
        cv.paint(r3, ellipsoid_sd(r3, (0.0, -5.0, 20.0), (2.5, 14.0, 8.0)), VENTRICLE)
    for sx in (-1.0, 1.0):  # lateral ventricles: the C (frontal horn to temporal horn), a wing, the occipital horn
        c_shape = [(9, 30, 32), (11, 12, 39), (13, -12, 41), (24, -34, 30), (32, -24, 8), (33, 0, -2)]
        wing = [(17, 28, 27), (19, 10, 33), (21, -12, 35)]  # the wing sloping down-laterally (coronal butterfly)
        paths = [make_path([(sx * x, y, z) for x, y, z in pts], rad, smooth=smooth)
                 for pts, rad, smooth in ((c_shape, [6.0, 6.0, 5.0, 7.0, 4.0, 2.5], True), (wing, 3.5, True),
                                          ([(24, -34, 30), (20, -56, 26)], [6.0, 2.5], False))]
        paint_tubes(cv, paths, [(0.0, VENTRICLE)])


def _paint_face(cv: Canvas) -> None:
    g, h = cv.grid, cv.reach  # h: the margin a painted edge needs
    for sx in (-1.0, 1.0):
        for c, semi in (((sx * 30.0, 48.0, -36.0), (13.0, 15.0, 14.0)),  # maxillary sinus
                        ((sx * 12.0, 70.0, 30.0), (9.0, 4.5, 8.0))):  # frontal sinus
            reg = g.around(c, np.add(semi, 2.5 + h))
            sd = ellipsoid_sd(reg, c, semi)
            cv.paint(reg, sd - 2.5, 1200.0)  # in a shell of bone
            cv.paint(reg, sd, -1000.0)
        eye = (sx * EYE_X, EYE_Y, 0.0)  # orbit: bony cone behind, fat around the globe
        orbit_c = (eye[0], EYE_Y - 4.0, 0.0)
        reg = g.around(orbit_c, 17.0 + 2.5 + h)
        orbit = sphere_sd(reg, orbit_c, 17.0)
        cv.paint(reg, np.maximum(orbit - 2.5, reg.y - (EYE_Y + 2.0)), 1300.0)
        cv.paint(reg, np.maximum(orbit, _body_sd(reg) + 2.0), -90.0)
        globe = sphere_sd(reg, eye, EYE_R)
        cv.paint(reg, globe, 45.0)  # sclera
        cv.paint(reg, globe + 1.2, 10.0)  # vitreous
        lens = (eye[0], EYE_Y + 8.5, 0.0)
        cv.paint(reg, ellipsoid_sd(reg, lens, (4.5, 2.0, 4.5)), 80.0)
    lo, hi = (-24.0, 25.0, -52.0), (24.0, 75.0, -48.0)  # hard palate
    reg = g.region(np.subtract(lo, h), np.add(hi, h))
    cv.paint(reg, box_sd(reg, lo, hi), 1100.0)
    jaw = [(-44, 0, -30), (-40, 5, -72), (-28, 35, -82), (0, 52, -88), (28, 35, -82), (40, 5, -72), (44, 0, -30)]
    paint_tubes(cv, [make_path(jaw, 5.5)], [(0.0, 1300.0)])


def _disc_sd(z: np.ndarray, z0: float, period: float, thickness: float) -> np.ndarray:
    """Signed distance (mm) to the discs: slabs ``thickness`` mm thick across z, starting at ``z0 + n period``."""
    u = np.mod(z - (z0 + thickness / 2.0) + period / 2.0, period) - period / 2.0  # from the nearest disc's middle
    return np.abs(u) - thickness / 2.0


def _paint_neck(cv: Canvas) -> None:
    """Cervical vertebrae (bodies and arches, discs between) and the spinal canal."""
    m = cv.reach
    reg = cv.grid.region((-12.0 - m, -58.0 - m, -200.0 - m), (12.0 + m, -18.0 + m, -52.0 + m))
    if reg is None:
        return
    disc = _disc_sd(reg.z, -200.0, 18.0, 4.0)
    body = ellipse_cylinder_sd(reg, (0.0, -28.0), (12.0, 10.0), (-200.0, -52.0))
    cv.paint(reg, body, 700.0)
    cv.paint(reg, np.maximum(body, disc), 80.0)
    arch = ellipse_cylinder_sd(reg, (0.0, -48.0), (10.0, 10.0), (-200.0, -52.0))
    cv.paint(reg, np.maximum(arch, -disc), 900.0)
    cv.paint(reg, arch + 4.0, 30.0)


def head(size=None, *, noise: float = 10.0, seed: int = 0, blur: float = 0.5, grey_white: bool = True) -> Volume:
    """Build the head phantom (see the module docstring); ``size`` defaults to 128 voxels along z (240 mm)."""
    grid = VoxelGrid.centred(FOV, 128 if size is None else size)
    cv = Canvas(grid, -1000.0, blur)
    full = grid.region()
    body = _body_sd(full)
    cv.paint(full, body, 40.0)
    cv.paint(full, body + 2.0, -100.0)
    cv.paint(full, body + SCALP, 45.0)
    del body
    _paint_neck(cv)
    _paint_skull_and_brain(cv, grey_white)
    _paint_face(cv)
    airway = make_path([(0, 95, -50), (0, 88, -41), (0, 70, -37), (0, 45, -37), (0, 20, -44), (0, 12, -60),
                        (0, 8, -85), (0, 5, -135)], [4.0, 5.0, 6.5, 6.5, 8.0, 8.0, 8.0, 8.0])
    mask = paint_tubes(cv, [airway], [(0.0, -1000.0)])  # open to the air at the nostrils

    marker_r = max(MARKER_R, 0.9 * max(grid.spacing))  # never smaller than a voxel: it must show
    marker_x = surface_point(_body_sd, (40.0, MARKER_Y, 0.0), (1.0, 0.0, 0.0), 80.0)[0] + marker_r
    marker = (marker_x, MARKER_Y, 0.0)
    reg = grid.around(marker, marker_r + cv.reach)
    cv.paint(reg, sphere_sd(reg, marker, marker_r), MARKER_HU)

    nasion = surface_point(_body_sd, (0.0, 40.0, 8.0), (0.0, 1.0, 0.0), 80.0)
    landmarks = {
        "center": list(SKULL_C),
        "vertex": [SKULL_C[0], SKULL_C[1], SKULL_C[2] + SKULL_AX[2]],
        "right_eye": [EYE_X, EYE_Y, 0.0],
        "left_eye": [-EYE_X, EYE_Y, 0.0],
        "nasion": [float(v) for v in nasion],
        "nose_tip": [float(v) for v in ellipsoid_support(NOSE_C, NOSE_AX, NOSE_ROT, (0.0, 1.0, 0.0))],
        "right_marker": [float(v) for v in marker],
    }
    truth = {"landmarks": landmarks, "nasal_airway": truth_tube("nasal_airway", mask, airway, grid),
             "eye_radius": EYE_R, "marker_radius": marker_r, "marker_hu": MARKER_HU}
    meta = {"truth": truth}
    return cv.to_volume(name="head", noise=noise, seed=seed, meta=meta)
