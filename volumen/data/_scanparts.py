"""Parts shared by the whole-region scans (``_abdomen``, ``_thorax``): the body's outline and wall, the table,
the spine and ribs, and the finish that makes a painted canvas read like a scan (texture, noise, the
reconstruction circle).

Coordinates as in ``_canvas``: RAS+ mm, the body's axis along z through ``(0, CY)``, the patient supine.
"""

from __future__ import annotations

import numpy as np

from ..core import Volume
from ._canvas import Canvas, Region
from ._grain import scanner_noise
from ._tubes import make_path, paint_tubes

__all__ = ["CY", "TABLE_Y", "FAT", "MUSCLE", "body_sd", "angle_sin", "paint_table", "paint_spine", "paint_ribs",
           "paint_wall", "finish_scan"]

CY = -8.0  # body centre (y); the back rests on the table
TABLE_Y = -126.0
FAT, MUSCLE = -105.0, 50.0


def body_sd(reg: Region, half_z: float, width=(168.0, 150.0), front=(108.0, 102.0), back: float = 117.0
            ) -> np.ndarray:
    """Signed distance (mm) to the skin: an ellipse per slice centred at ``(0, CY)``, its semi-axes going linearly
    from the bottom slice to the top one (``width`` along x, ``front`` in front of the centre), ``back`` behind."""
    t = (reg.z + half_z) / (2.0 * half_z)  # 0 at the bottom, 1 at the top
    a = width[0] + (width[1] - width[0]) * t
    b = np.where(reg.y >= CY, front[0] + (front[1] - front[0]) * t, back + 0.0 * t)
    ux, uy = reg.x / a, (reg.y - CY) / b
    f = ux * ux + uy * uy
    grad = np.sqrt((ux / a) ** 2 + (uy / b) ** 2)
    return ((f - 1.0) / (2.0 * np.maximum(grad, 1e-6))).astype(np.float32)


def angle_sin(reg: Region) -> np.ndarray:
    """sin of the angle around the body's axis: +1 in front, -1 at the back."""
    dy = reg.y - CY
    return (dy / np.sqrt(reg.x * reg.x + dy * dy + 1e-6)).astype(np.float32)


def paint_table(cv: Canvas) -> None:
    """The table under the back: a curved carbon-fibre shell (+150 HU, 2 mm) over foam (-850), 40 mm deep."""
    reg = cv.grid.region((-230.0, TABLE_Y - 60.0, -1e3), (230.0, TABLE_Y + 5.0, 1e3))
    if reg is None:
        return
    top = TABLE_Y + 0.0012 * reg.x * reg.x  # the table's top curves up at the sides
    slab = np.maximum(np.maximum(reg.y - top, top - 40.0 - reg.y), np.abs(reg.x) - 210.0)
    cv.paint(reg, slab + 0.0 * reg.z, 150.0)
    cv.paint(reg, slab + 2.0 + 0.0 * reg.z, -850.0)


def paint_spine(cv: Canvas, x0: float, y0: float, lo: float, hi: float) -> None:
    """Vertebrae along z from ``lo`` to ``hi`` mm, body centred at (x0, y0): cortex, cancellous bone, discs,
    the arch around the spinal canal and the spinous process."""
    m = cv.reach
    reg = cv.grid.region((x0 - 30.0 - m, y0 - 50.0 - m, lo), (x0 + 30.0 + m, y0 + 22.0 + m, hi))
    if reg is None:
        return
    u = np.mod(reg.z - lo, 40.0) - 20.0  # 30 mm bodies, 10 mm discs
    disc = (np.abs(u) - 15.0).astype(np.float32)  # > 0 in a disc
    dx, dy = reg.x - x0, reg.y - y0
    body = (np.sqrt((dx / 22.0) ** 2 + (dy / 18.0) ** 2) - 1.0) * 18.0 + 0.0 * reg.z
    cv.paint(reg, body, 90.0)
    cv.paint(reg, np.maximum(body, disc), 750.0)
    cv.paint(reg, np.maximum(body + 1.6, disc + 1.6), 230.0)
    arch = np.sqrt(dx * dx + (dy + 30.0) ** 2) - 13.0 + 0.0 * reg.z
    cv.paint(reg, np.maximum(arch, disc + 2.0), 650.0)
    spinous = np.maximum(np.abs(dx) - 4.0, np.abs(reg.y - (y0 - 42.0)) - 8.0) + 0.0 * reg.z
    cv.paint(reg, np.maximum(spinous, disc + 2.0), 650.0)
    cv.paint(reg, arch + 5.0, 20.0)  # the canal


def paint_ribs(cv: Canvas, tops, ends, half_axes, drop: float) -> None:
    """Ribs from the spine around the body: one pair per top height (mm), ending at ``ends`` (degrees, 0 at
    the side, 90 in front) and falling ``drop`` mm on the way; cortex +800 around marrow +250, costal
    cartilage (+150) on to the front."""
    bones, cartilage = [], []
    for z0, end in zip(tops, ends, strict=True):
        theta = np.radians(np.linspace(-105.0, end, 20))
        fall = drop * (theta - theta[0]) / np.radians(180.0)
        for sx in (-1.0, 1.0):
            pts = np.stack([sx * half_axes[0] * np.cos(theta), CY + half_axes[1] * np.sin(theta), z0 - fall], axis=1)
            bones.append(make_path(pts, 5.0))
            th2 = np.radians(np.linspace(end, 82.0, 6))
            if end < 80.0:
                c2 = np.stack([sx * half_axes[0] * np.cos(th2), CY + half_axes[1] * np.sin(th2),
                               np.full(6, z0 - fall[-1])], axis=1)
                cartilage.append(make_path(c2, 4.0, smooth=False))
    if cartilage:
        paint_tubes(cv, cartilage, [(0.0, 150.0)])
    paint_tubes(cv, bones, [(0.0, 800.0), (-1.5, 250.0)])


def paint_wall(cv: Canvas, sd: np.ndarray, fat: np.ndarray, muscle, inside: float) -> None:
    """The body wall on the whole grid: skin (+30 HU, 2.5 mm), fat (``fat`` mm), muscle (``muscle`` mm), then
    ``inside`` HU."""
    reg = cv.grid.region()
    cv.paint(reg, sd, 30.0)
    cv.paint(reg, sd + 2.5, FAT)
    cv.paint(reg, sd + 2.5 + fat, MUSCLE)
    cv.paint(reg, sd + 2.5 + fat + muscle, inside)


def finish_scan(cv: Canvas, fine: np.ndarray, *, noise: float, seed: int, name: str, meta: dict) -> Volume:
    """Tissue texture (``fine``: a unit field; fat +-14 HU, soft tissue +-5 HU), the scanner's correlated noise
    (``noise`` HU, 0.7 mm), the reconstruction circle (-1024 HU beyond the in-plane field's inscribed circle)
    and int16 HU clipped to a scanner's range."""
    d = cv.data
    amp = np.where(d < -50.0, 14.0, np.where(d < 200.0, 5.0, 0.0)).astype(np.float32)
    amp *= d > -600.0
    d += amp * fine
    del amp
    if noise > 0:
        d += scanner_noise(cv.grid, noise, 0.7, seed + 1)
    reg = cv.grid.region()
    radius = 0.5 * min(cv.grid.shape[2] * cv.grid.spacing[2], 400.0)
    d[np.broadcast_to(reg.x * reg.x + reg.y * reg.y > radius * radius, d.shape)] = -1024.0
    out = np.clip(np.rint(d), -1024, 3071).astype(np.int16)
    return Volume(out, spacing=cv.grid.spacing, affine=cv.grid.affine, modality="CT", units="HU", name=name,
                  meta=meta)
