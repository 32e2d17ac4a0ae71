"""The layered-aorta phantom: a large contrast vessel whose contrast is uneven, beside lung and a bright neighbour.

What a contrast chest CT shows of the ascending aorta when the bolus is not ideal, in Hounsfield units, on
1.5 mm voxels (head end toward +z, front toward +y, the patient's right toward +x): the failure class of a
lumen estimate read from the clicked voxel's neighbourhood.

* the aorta (radius 13 mm, a gentle S along z, 2 mm wall of +45) filled with contrast of 450 HU, layered:
  ``layering`` HU brighter at its back than at its front (contrast settling toward the patient's back),
  and mixed: a jet of unopacified blood (about 120 HU) entering from its right side and fading into the
  lumen over a few centimetres, so the lumen's values run from about 100 to 480 HU;
* a second contrast vessel (radius 9 mm, 330 HU, 1.5 mm wall) beside it on its left, the walls touching: a
  bright neighbour 3.5 mm of wall away;
* mediastinal fat (-90) round both, and the lung (-850, varying by 40 HU) from ``gap`` mm (default 10) past
  the aorta's wall at its back-right;
* correlated scanner noise (``noise`` HU, default 40, correlated over 1 mm: the grain of a real CT), every
  surface a blurred partial-volume edge.

``meta["truth"]``: ``aorta`` (:class:`Tube`, its ``mask`` the lumen), ``neighbour`` (bool mask of the
neighbour's lumen), ``lung`` (bool mask), ``landmarks``: ``starts`` (20 points along the aorta's centerline,
each up to half its radius off the axis, deterministic).
"""

from __future__ import annotations

import numpy as np

from ..core import Volume
from ._canvas import Canvas, VoxelGrid, ellipsoid_sd
from ._grain import scanner_noise
from ._texture import smooth_field
from ._tubes import make_path, truth_tube, tube_field

__all__ = ["layered_aorta"]

FOV = (120.0, 120.0, 150.0)  # x, y, z mm
FAT, WALL_HU, LUNG, CONTRAST, NEIGHBOUR, JET = -90.0, 45.0, -850.0, 450.0, 330.0, 120.0
AORTA = ([(6, 4, -70), (10, 6, -30), (6, 2, 10), (2, -2, 45), (4, -2, 70)], 13.0)
NEIGHBOUR_PATH = ([(-21, 6, -70), (-17, 8, -30), (-21, 4, 10), (-25, 0, 45), (-23, 0, 70)], 9.0)
JET_CENTRE, JET_SIZE = (20.0, 6.0, -20.0), (10.0, 10.0, 22.0)  # mm: where unopacified blood enters, and its extent
LUNG_CENTRE = (60.0, -45.0, 0.0)  # the lung's ellipsoid, back-right of the aorta
STARTS = 20


def _contrast(grid: VoxelGrid, field, path, layering: float, seed: int) -> np.ndarray:
    """The aorta's values on its field's region: layered front to back, mixed with the jet, a little uneven."""
    reg = field.region
    centre_y = np.interp(field.arc, path.arc, path.points[:, 1])
    behind = np.clip((centre_y - reg.y) / (2.0 * 13.0), -0.5, 0.5)  # -0.5 at the front, 0.5 at the back
    jet_sd = ellipsoid_sd(reg, JET_CENTRE, JET_SIZE)
    jet = np.exp(-0.5 * np.maximum(jet_sd + 6.0, 0.0) ** 2 / 36.0)  # 1 inside the jet's core, fading over 6 mm
    mixing = 1.0 + 0.05 * smooth_field(grid, 8.0, seed + 2)[reg.slices]
    value = (CONTRAST + layering * behind) * mixing
    return (value + jet * (JET - value)).astype(np.float32)


def _starts(path, radius: float) -> np.ndarray:
    """``STARTS`` points along the middle 80 % of the path, each off the axis by up to half the radius."""
    rng = np.random.default_rng(7)
    idx = np.linspace(0.1 * len(path.points), 0.9 * len(path.points), STARTS).astype(int)
    off = rng.normal(size=(STARTS, 3))
    t = np.gradient(path.points, axis=0)[idx]
    t /= np.linalg.norm(t, axis=1, keepdims=True)
    off -= np.einsum("ij,ij->i", off, t)[:, None] * t
    off *= (0.5 * radius * rng.random(STARTS) / np.linalg.norm(off, axis=1))[:, None]
    return path.points[idx] + off


def layered_aorta(size=None, *, noise: float = 40.0, seed: int = 0, blur: float = 0.6, layering: float = 150.0,
                  gap: float = 10.0) -> Volume:
    """Build the layered-aorta phantom (see the module docstring); ``size`` defaults to 100 voxels along the
    longest axis (1.5 mm)."""
    if not 30.0 <= noise <= 60.0:
        raise ValueError(f"noise must be within [30, 60] HU (a real CT's grain), got {noise!r}")
    if not gap >= 3.0:
        raise ValueError(f"gap must be at least 3 mm, got {gap!r}")
    grid = VoxelGrid.centred(FOV, 100 if size is None else size)
    cv = Canvas(grid, FAT, blur)
    reg = grid.region()
    aorta, neighbour = make_path(*AORTA), make_path(*NEIGHBOUR_PATH)
    fa, fn = tube_field(grid, aorta, 30.0 + gap), tube_field(grid, neighbour, cv.reach + 2.0)
    away = np.full(grid.shape, np.inf, np.float32)
    away[fa.region.slices] = fa.sdf
    lung_sd = np.maximum(ellipsoid_sd(reg, LUNG_CENTRE, (60.0, 55.0, 120.0)), np.float32(2.0 + gap) - away)
    cv.paint(reg, lung_sd, LUNG + 40.0 * smooth_field(grid, 15.0, seed + 1))
    cv.paint(fn.region, fn.sdf - np.float32(1.5), WALL_HU)
    cv.paint(fn.region, fn.sdf, NEIGHBOUR)
    cv.paint(fa.region, fa.sdf - np.float32(2.0), WALL_HU)
    cv.paint(fa.region, fa.sdf, _contrast(grid, fa, aorta, layering, seed))
    cv.data += scanner_noise(grid, noise, 1.0, seed + 3)
    mask = np.zeros(grid.shape, bool)
    mask[fa.region.slices] = fa.sdf < 0
    other = np.zeros(grid.shape, bool)
    other[fn.region.slices] = fn.sdf < 0
    tube = truth_tube("aorta", mask, aorta, grid)
    truth = {"aorta": tube, "neighbour": other, "lung": lung_sd < 0,
             "landmarks": {"starts": _starts(aorta, 13.0).tolist()}}
    return cv.to_volume(name="layered_aorta", noise=0.0, seed=seed, meta={"truth": truth})
