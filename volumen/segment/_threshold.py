"""Thresholding: value ranges in the volume's units -> mask."""

from __future__ import annotations

import numpy as np

from ..core import Volume
from ._mask import mask_like

__all__ = ["threshold"]


def threshold(volume: Volume, lo: float | None = None, hi: float | None = None, *,
              ranges=None) -> Volume:
    """Mask of the voxels whose value lies in ``[lo, hi]`` (inclusive), or in any of ``ranges``.

    Parameters
    ----------
    volume : Volume
        The scalar volume; ``lo`` and ``hi`` are in its units (HU for CT).
    lo, hi : float, optional
        Inclusive bounds; a missing one is open (-inf or +inf).
    ranges : sequence of (lo, hi), optional
        Several inclusive ranges whose union is kept; not together with ``lo``/``hi``.

    Returns
    -------
    Volume
        uint8 0/1 mask on the same grid (``meta["threshold"]`` lists the ranges).
    """
    if ranges is not None and (lo is not None or hi is not None):
        raise ValueError("give either lo/hi or ranges, not both")
    if ranges is None:
        ranges = [(-np.inf if lo is None else lo, np.inf if hi is None else hi)]
    ranges = [(float(a), float(b)) for a, b in ranges]
    if not ranges:
        raise ValueError("ranges is empty")
    for a, b in ranges:
        if np.isnan(a) or np.isnan(b) or a > b:
            raise ValueError(f"bad threshold range [{a}, {b}]: need lo <= hi")
    data = volume.data
    out = np.zeros(volume.shape, bool)
    for a, b in ranges:
        out |= (data >= a) & (data <= b)
    return mask_like(volume, out, threshold=ranges)
