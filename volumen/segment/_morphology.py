"""Binary morphology with ball structuring elements of a radius in millimetres."""

from __future__ import annotations

import numpy as np

from ..core import Volume
from ._mask import mask_data, mask_like

__all__ = ["ball", "dilate", "erode", "binary_open", "binary_close", "fill_holes"]


def ball(radius_mm: float, spacing) -> np.ndarray:
    """Ball footprint of ``radius_mm`` on a grid of ``spacing`` ``(dz, dy, dx)`` mm.

    Returns
    -------
    (2 rz + 1, 2 ry + 1, 2 rx + 1) bool
        True where ``(z dz)^2 + (y dy)^2 + (x dx)^2 <= radius^2``, indexed ``[z, y, x]``
        around the centre; ``r_a = floor(radius / d_a)``. Anisotropic spacing gives an
        ellipsoid of voxels that is a ball in millimetres.
    """
    sp = np.asarray(spacing, dtype=float).ravel()
    if sp.shape != (3,) or np.any(sp <= 0):
        raise ValueError(f"spacing must be three positive mm values (dz, dy, dx), got {spacing}")
    if not radius_mm >= 0:
        raise ValueError(f"radius must be >= 0 mm, got {radius_mm}")
    half = np.floor(radius_mm / sp + 1e-9).astype(int)
    z, y, x = np.ogrid[-half[0]:half[0] + 1, -half[1]:half[1] + 1, -half[2]:half[2] + 1]
    return (z * sp[0]) ** 2 + (y * sp[1]) ** 2 + (x * sp[2]) ** 2 <= radius_mm ** 2 * (1 + 1e-9)


def _apply(mask: Volume, radius_mm: float, op: str) -> Volume:
    from scipy import ndimage

    m = mask_data(mask)
    fp = ball(radius_mm, mask.spacing)
    if op == "dilate":
        out = ndimage.binary_dilation(m, structure=fp)
    elif op == "erode":
        out = ndimage.binary_erosion(m, structure=fp)
    elif op == "open":
        out = ndimage.binary_opening(m, structure=fp)
    else:  # close: pad so the erosion does not eat what touches the border
        pad = [(h, h) for h in (np.array(fp.shape) - 1) // 2]
        out = ndimage.binary_closing(np.pad(m, pad), structure=fp)
        out = out[tuple(slice(a, a + n) for (a, _), n in zip(pad, m.shape, strict=True))]
    return mask_like(mask, out, morphology=(op, float(radius_mm)))


def dilate(mask: Volume, radius_mm: float) -> Volume:
    """Binary dilation by a ball of ``radius_mm`` (see :func:`ball`)."""
    return _apply(mask, radius_mm, "dilate")


def erode(mask: Volume, radius_mm: float) -> Volume:
    """Binary erosion by a ball of ``radius_mm``; outside the volume counts as background."""
    return _apply(mask, radius_mm, "erode")


def binary_open(mask: Volume, radius_mm: float) -> Volume:
    """Opening (erosion then dilation) by a ball: removes specks and thin bridges narrower than the ball."""
    return _apply(mask, radius_mm, "open")


def binary_close(mask: Volume, radius_mm: float) -> Volume:
    """Closing (dilation then erosion) by a ball: fills gaps and dents narrower than the ball.

    The mask is padded by the ball's half-size first, so closing never erodes
    structures that touch the volume's border.
    """
    return _apply(mask, radius_mm, "close")


def fill_holes(mask: Volume) -> Volume:
    """Fill the cavities of a mask: background not connected (6-connectivity) to the border."""
    from scipy import ndimage

    return mask_like(mask, ndimage.binary_fill_holes(mask_data(mask)))
