"""The abdomen CT: a whole-abdomen scan in the portal-venous phase, as a benchmark sees one.

Built for speed measurements that must hold on scans like the ones people look at: soft
tissue fills most of the picture, so almost every ray crosses centimetres of fat, muscle and organs
at a low but non-zero opacity in the translucent presets. Head end toward +z, front toward +y, the
patient's right toward +x, lying supine on the scanner's table; a square-ish field of view of 400 x
331 x 367 mm from the lung bases to the iliac crests. Painted back to front on a float canvas
(``_canvas``), every surface a partial-volume edge blurred by the scanner:

* outside: air, the carbon-fibre table (a thin shell over foam) under the back, and the reconstruction
  circle (-1024 HU beyond it);
* body wall: skin (+30 HU), subcutaneous fat (-105, thicker in front), muscle (+50), paraspinal muscles
  and psoas;
* visceral fat (-95) filling the cavity around liver (+105) with portal and hepatic veins (+165), spleen
  (+115), kidneys (cortex +170, medulla +110, sinus fat), pancreas (+95), gallbladder (+10), the stomach
  (gas in front of a fluid level), the colon (gas in front, mottled stool behind) and small-bowel loops
  (fluid, some gas), the aorta (+170) and its iliac arteries, the inferior vena cava (+130);
* the lung bases (-860) behind and above the diaphragm, the heart's apex;
* bone: lumbar vertebrae (cancellous +230 in a +750 cortex) with discs (+90), lower ribs and costal
  cartilage (+150), iliac wings and sacrum.

Then tissue texture (fat strands, organ mottling: ``_grain.texture_field``) and the scanner's
correlated noise (``_grain.scanner_noise``: 12 HU, 0.7 mm; ``_scanparts.finish_scan``). Deterministic for a
given size and seed.

``meta["truth"]["landmarks"]``: name -> xyz world mm.
"""

from __future__ import annotations

import numpy as np

from ..core import Volume
from ._canvas import Canvas, Region, VoxelGrid, ellipsoid_sd, smooth_union
from ._grain import texture_field
from ._scanparts import CY, MUSCLE, angle_sin, body_sd, finish_scan, paint_ribs, paint_spine, paint_table, paint_wall
from ._tubes import make_path, paint_tubes, tube_field

__all__ = ["abdomen"]

FOV = (400.0, 331.0, 367.0)  # x, y, z mm
AIR, VFAT = -1000.0, -95.0
LIVER = ((70.0, 0.0, 95.0), (78.0, 85.0, 82.0))
LIVER_LEFT = ((-5.0, 40.0, 120.0), (65.0, 38.0, 38.0))
SPLEEN = ((-85.0, -40.0, 95.0), (38.0, 35.0, 55.0))
STOMACH = ((-45.0, 35.0, 105.0), (48.0, 42.0, 58.0))
GALLBLADDER = ((50.0, 50.0, 35.0), (16.0, 15.0, 35.0))
KIDNEY = ((70.0, -50.0, 10.0), (27.0, 24.0, 55.0))
COLON = ([(105, -10, -160), (110, -5, -20), (100, 25, 45), (55, 62, 30), (0, 72, 15), (-60, 60, 45),
          (-100, 15, 85), (-115, -15, 20), (-110, -20, -90), (-85, 10, -150), (-30, 35, -170), (5, 10, -195)],
         [26, 26, 24, 22, 22, 22, 20, 18, 18, 17, 17, 16])
AORTA = ([(-18, -38, 200), (-18, -36, 40), (-12, -30, -115), (-45, -20, -200)], 11.0)
AORTA_R = ([(-12, -30, -115), (40, -22, -200)], 8.0)
IVC = ([(24, -34, 200), (22, -34, 40), (14, -36, -125), (40, -30, -200)], 12.0)
PANCREAS = ([(28, 5, 25), (0, 12, 35), (-45, -5, 50), (-80, -25, 62)], [15.0, 12.0, 11.0, 10.0])


def dome(reg: Region) -> np.ndarray:
    """Height (z mm) of the diaphragm over (x, y): a dome, higher on the right, falling to the back and sides."""
    return (160.0 - 0.0035 * (reg.y - 20.0) ** 2 - 0.0012 * reg.x * reg.x
            + 12.0 * np.exp(-(((reg.x - 60.0) / 70.0) ** 2)) + 0.0 * reg.z)


def _paint_wall(cv: Canvas, half_z: float, tex: np.ndarray) -> None:
    reg = cv.grid.region()
    paint_wall(cv, body_sd(reg, half_z), 20.0 + 8.0 * angle_sin(reg) + 3.0 * tex, 11.5, VFAT)
    m = cv.reach
    for sx in (-1.0, 1.0):  # paraspinal muscles and psoas
        r = cv.grid.region((sx * 38.0 - 30.0 - m, CY - 120.0, -1e3), (sx * 38.0 + 30.0 + m, CY - 55.0 + m, 1e3))
        cv.paint(r, ellipsoid_sd(r, (sx * 38.0, CY - 92.0, 0.0), (28.0, 24.0, 1e4)), MUSCLE)
        r = cv.grid.region((sx * 42.0 - 30.0 - m, -90.0, -1e3), (sx * 42.0 + 30.0 + m, -20.0, 30.0))
        if r is not None:
            semi = 9.0 + 16.0 * np.clip((20.0 - r.z) / 200.0, 0.0, 1.0)
            rr = np.sqrt(((r.x - sx * 42.0) / semi) ** 2 + ((r.y + 55.0) / semi) ** 2) - 1.0
            cv.paint(r, rr * semi + np.maximum(r.z - 20.0, 0.0), MUSCLE)


def _paint_organs(cv: Canvas, half_z: float, tex: np.ndarray) -> None:
    g, m = cv.grid, cv.reach
    r = g.region((-75.0, -90.0, 0.0), (150.0, 90.0, 185.0))
    liver = smooth_union(ellipsoid_sd(r, *LIVER), ellipsoid_sd(r, *LIVER_LEFT), 20.0)
    liver = np.maximum(np.maximum(liver, body_sd(r, half_z) + 28.0), r.z - dome(r) + 3.0)
    cv.paint(r, liver, 105.0 + 8.0 * tex[r.slices])
    veins = [make_path([(35, 0, 40), (55, 10, 80), (80, 0, 130)], 6.0),
             make_path([(55, 10, 80), (40, 30, 120)], 4.5),
             make_path([(35, 0, 40), (20, 15, 90), (0, 20, 140)], 5.0),
             make_path([(24, -30, 150), (70, -10, 150)], 6.0)]
    paint_tubes(cv, veins, [(0.0, 165.0)])
    r = g.around(SPLEEN[0], np.add(SPLEEN[1], m))
    spleen = np.maximum(ellipsoid_sd(r, *SPLEEN), body_sd(r, half_z) + 26.0)
    cv.paint(r, np.maximum(spleen, r.z - dome(r) + 3.0), 115.0 + 5.0 * tex[r.slices])
    r = g.around(GALLBLADDER[0], np.add(GALLBLADDER[1], m))
    cv.paint(r, ellipsoid_sd(r, *GALLBLADDER), 10.0)
    for sx in (-1.0, 1.0):
        c = (sx * KIDNEY[0][0], KIDNEY[0][1], KIDNEY[0][2] - (8.0 if sx > 0 else 0.0))
        r = g.around(c, np.add(KIDNEY[1], m))
        cv.paint(r, ellipsoid_sd(r, c, KIDNEY[1]), 170.0)
        cv.paint(r, ellipsoid_sd(r, c, np.multiply(KIDNEY[1], 0.62)), 110.0)
        sinus = (c[0] - sx * 14.0, c[1] + 4.0, c[2])
        cv.paint(r, ellipsoid_sd(r, sinus, (9.0, 8.0, 22.0)), -80.0)
    paint_tubes(cv, [make_path(*PANCREAS)], [(0.0, 95.0)])
    r = g.around(STOMACH[0], np.add(STOMACH[1], m))
    sd = np.maximum(ellipsoid_sd(r, *STOMACH), r.z - dome(r) + 3.0)
    cv.paint(r, sd, 60.0)
    cv.paint(r, sd + 4.0, np.where(r.y > STOMACH[0][1] + 10.0, AIR, 15.0))
    paint_tubes(cv, [make_path(*AORTA), make_path(*AORTA_R)], [(1.5, 45.0), (0.0, 170.0)])
    paint_tubes(cv, [make_path(*IVC)], [(0.0, 130.0)])
    sma = [make_path([(-18, -26, 30), (-14, 10, 10), (-10, 25, -40), (-5, 30, -110)], 4.0),
           make_path([(5, -24, 35), (8, 14, 10), (12, 28, -40), (16, 32, -110)], 5.0)]
    paint_tubes(cv, sma, [(0.0, 160.0)])


def _paint_tube(cv: Canvas, path, wall: float, wall_hu: float, contents, gas_above: float) -> None:
    """A hollow organ along ``path``: a wall ``wall`` mm thick, ``contents`` (HU, or an array on the grid) inside
    and gas above the level ``y = gas_above`` mm (the patient lies supine: gas rises to the front)."""
    f = tube_field(cv.grid, path, wall + cv.reach)
    if f is None:
        return
    reg = f.region
    cv.paint(reg, f.sdf - np.float32(wall), wall_hu)
    cv.paint(reg, f.sdf, contents if np.ndim(contents) == 0 else contents[reg.slices])
    cv.paint(reg, np.maximum(f.sdf, gas_above - reg.y), AIR)


def _paint_bowel(cv: Canvas, seed: int, stool: np.ndarray) -> None:
    rng = np.random.default_rng(seed)
    for i in range(12):  # small bowel: random loops in the lower middle abdomen, a third with gas in front
        pts = rng.uniform((-80.0, -15.0, -165.0), (75.0, 75.0, 5.0), (6, 3))
        level = float(pts[:, 1].mean()) + 6.0 if i % 3 == 0 else 1e3
        _paint_tube(cv, make_path(pts, 12.0), 2.0, 55.0, 20.0, level)
    _paint_tube(cv, make_path(*COLON), 2.5, 50.0, stool, 40.0)


def _paint_chest_base(cv: Canvas) -> None:
    g, m = cv.grid, cv.reach
    for sx in (-1.0, 1.0):  # lung bases: behind and above the diaphragm's domes
        r = g.region((sx * 85.0 - 62.0 - m, -110.0, 60.0), (sx * 85.0 + 62.0 + m, 65.0, 1e3))
        if r is None:
            continue
        lung = np.maximum(ellipsoid_sd(r, (sx * 85.0, -20.0, 250.0), (62.0, 82.0, 1e3)), dome(r) - r.z)
        lung = np.maximum(lung, 28.0 - sx * r.x)
        cv.paint(r, lung, -860.0)
    r = g.around((-30.0, 40.0, 215.0), (60.0 + m, 50.0 + m, 55.0 + m))
    if r is not None:
        heart = ellipsoid_sd(r, (-30.0, 40.0, 215.0), (60.0, 50.0, 55.0))
        cv.paint(r, heart, 60.0)
        cv.paint(r, heart + 9.0, 150.0)


def _paint_pelvis(cv: Canvas) -> None:
    g, m = cv.grid, cv.reach
    for sx in (-1.0, 1.0):  # iliac wings: curved plates, their crests at about z = -115
        c = (sx * 55.0, -40.0, -215.0)
        r = g.around(c, (95.0 + m, 70.0 + m, 100.0 + m))
        if r is None:
            continue
        shell = np.abs(ellipsoid_sd(r, c, (90.0, 62.0, 100.0)) + 5.0) - 5.0
        wing = np.maximum(shell, np.maximum(-sx * (r.x - c[0]) + 10.0, r.y - 15.0))
        cv.paint(r, wing, 800.0)
        cv.paint(r, wing + 1.5, 300.0)
    r = g.around((0.0, -85.0, -220.0), (45.0 + m, 25.0 + m, 70.0 + m))
    if r is not None:
        sacrum = ellipsoid_sd(r, (0.0, -85.0, -220.0), (45.0, 22.0, 70.0))
        cv.paint(r, sacrum, 750.0)
        cv.paint(r, sacrum + 1.6, 280.0)


def abdomen(size=None, *, noise: float = 12.0, seed: int = 0, blur: float = 0.6) -> Volume:
    """Build the abdomen CT (see the module docstring); ``size`` defaults to (224, 202, 244) voxels (nz, ny, nx),
    1.64 mm."""
    grid = VoxelGrid.centred(FOV, (224, 202, 244) if size is None else size)
    half_z = FOV[2] / 2.0
    cv = Canvas(grid, AIR, blur)
    coarse = texture_field(grid, 24.0, seed + 2)
    paint_table(cv)
    _paint_wall(cv, half_z, coarse)
    _paint_chest_base(cv)
    _paint_organs(cv, half_z, coarse)
    fine = texture_field(grid, 5.0, seed + 3)
    _paint_bowel(cv, seed, -250.0 + 260.0 * np.clip(fine, -1.5, 1.5))
    del coarse
    paint_spine(cv, 0.0, -65.0, -1e3, 1e3)
    paint_ribs(cv, (215.0, 195.0, 175.0, 155.0, 135.0, 115.0), (55.0, 45.0, 35.0, 20.0, 5.0, -15.0),
               (150.0, 100.0), 80.0)
    _paint_pelvis(cv)
    landmarks = {"liver": list(LIVER[0]), "spleen": list(SPLEEN[0]), "right_kidney": list(KIDNEY[0]),
                 "left_kidney": [-KIDNEY[0][0], *KIDNEY[0][1:]], "stomach": list(STOMACH[0])}
    return finish_scan(cv, fine, noise=noise, seed=seed, name="abdomen", meta={"truth": {"landmarks": landmarks}})
