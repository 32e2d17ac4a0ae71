"""The page's three slice views: windowed axial, coronal and sagittal slices through a world point, as PNG.

Drawn by ``volumen.core.slice_image`` in radiological display orientation (axial seen from the feet with the
patient's right on the left; coronal from the front; sagittal from the patient's left), square pixels.
:func:`slice_png` also returns the slice's pixel -> world map (a click on the picture moves the crosshair to
the world point under it) and where the two other planes cut it (the page draws those lines).
"""

from __future__ import annotations

import functools
import io
import weakref

import numpy as np

from volumen.core import PLANES, Window, canonical, slice_image

__all__ = ["slice_png", "pixel_map"]

#: numpy axis of the canonical volume each plane cuts, and the (row, column) voxel axes of its picture
_AXES = {"axial": (0, (1, 2)), "coronal": (1, (0, 2)), "sagittal": (2, (0, 1))}
_canonical: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _can(volume):
    c = _canonical.get(volume)
    if c is None:
        c = _canonical[volume] = canonical(volume)
    return c


@functools.lru_cache(maxsize=64)
def _zoomed(n_in: int, n_out: int) -> float:
    """Input pixel per output pixel of ``ndimage.zoom`` (corners aligned)."""
    return (n_in - 1) / (n_out - 1) if n_out > 1 else 0.0


def pixel_map(can, plane: str, index: int, out_shape) -> np.ndarray:
    """(3, 3) float: world mm of the displayed pixel centre ``(col, row)`` is ``m[0] + col m[1] + row m[2]``."""
    ax, (ra, ca) = _AXES[plane]
    nz, ny, nx = can.shape
    n = (nz, ny, nx)
    # display flips: axial rows A->P (j reversed) and columns R->L (i reversed); coronal / sagittal rows S->I
    # (k reversed), coronal columns R->L (i reversed), sagittal columns A->P (j reversed)
    def voxel(row, col):
        zyx = [0.0, 0.0, 0.0]
        zyx[ax] = float(index)
        zyx[ra] = n[ra] - 1 - row * _zoomed(n[ra], out_shape[0])
        zyx[ca] = n[ca] - 1 - col * _zoomed(n[ca], out_shape[1])
        return can.index_to_world([zyx[2], zyx[1], zyx[0]])

    o = voxel(0.0, 0.0)
    return np.array([o, voxel(0.0, 1.0) - o, voxel(1.0, 0.0) - o])


def slice_png(volume, plane: str, world, level: float, width: float) -> tuple[bytes, np.ndarray, dict]:
    """``(PNG bytes, pixel map, crossing)`` of the ``plane`` slice through the world point ``world`` (mm) with
    the window ``level`` / ``width`` (data units). ``crossing``: where the other two planes through ``world``
    cut the picture, ``{"row": r, "col": c, "row_plane": name, "col_plane": name}`` (the page draws them as
    lines in the planes' colours, at any scale)."""
    if plane not in PLANES:
        raise ValueError(f"unknown plane {plane!r}; valid: {', '.join(PLANES)}")
    world = np.asarray(world, float)
    if world.shape != (3,) or not np.all(np.isfinite(world)):
        raise ValueError("the slice point must be three finite numbers (mm)")
    if not (np.isfinite(level) and np.isfinite(width) and width > 0):
        raise ValueError("the window needs a finite level and a width > 0")
    can = _can(volume)
    ijk = np.clip(np.rint(can.world_to_index(world)), 0, np.array(can.shape[::-1]) - 1).astype(int)
    ax, (ra, ca) = _AXES[plane]
    index = int(ijk[2 - ax])
    gray = slice_image(can, plane, index=index, window=Window(level=level, width=width), canonical_volume=can)
    m = pixel_map(can, plane, index, gray.shape[:2])
    col, row = np.linalg.lstsq(m[1:].T, world - m[0], rcond=None)[0]   # the world point on this picture
    by_axis = {a: p for p, (a, _) in _AXES.items()}
    crossing = {"row": float(row), "col": float(col), "row_plane": by_axis[ra], "col_plane": by_axis[ca]}
    return _png(gray), m, crossing


def _png(rgb: np.ndarray) -> bytes:
    from PIL import Image as PILImage

    buf = io.BytesIO()
    PILImage.fromarray(np.ascontiguousarray(rgb, np.uint8)).save(buf, format="PNG")
    return buf.getvalue()
