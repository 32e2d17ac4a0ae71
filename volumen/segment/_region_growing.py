"""Region growing from seed points over a value range."""

from __future__ import annotations

from typing import Literal

import numpy as np

from ..core import Volume
from ._connectivity import neighbour_offsets
from ._mask import mask_like
from ._seeds import seed_indices

__all__ = ["region_grow"]


def region_grow(volume: Volume, seeds, *, lo: float | None = None, hi: float | None = None,
                tolerance: float | None = None, connectivity: int = 6,
                space: Literal["world", "voxel"] = "world") -> Volume:
    """The voxels connected to the seeds through values in a range.

    Parameters
    ----------
    volume : Volume
        The scalar volume; bounds are in its units (HU for CT).
    seeds : (3,) or (n, 3) float
        Seed points, world RAS+ mm ``(x, y, z)`` or voxel ``(i, j, k)`` (see ``space``);
        each is moved to its nearest voxel.
    lo, hi : float, optional
        Inclusive value range; a missing bound is open.
    tolerance : float, optional
        Instead of ``lo``/``hi``: the range ``mean(seed values) +- tolerance``.
    connectivity : {6, 18, 26}
        Voxel neighbourhood: faces only (6), faces and edges (18), all (26).
    space : {"world", "voxel"}
        How the seeds are given.

    Returns
    -------
    Volume
        uint8 0/1 mask on the same grid; ``meta["range"]`` is the range used and
        ``meta["voxels"]`` the voxel count.

    Raises
    ------
    ValueError
        Bad arguments, a seed outside the volume, or no seed whose value is in the range.

    Notes
    -----
    A compiled breadth-first flood fill: it visits only the region and its border, so it
    beats labelling the whole thresholded volume (``scipy.ndimage.label``) and keeping
    the seeds' components, which gives the same mask.
    """
    from ._region_growing_kernel import flood

    if tolerance is not None and (lo is not None or hi is not None):
        raise ValueError("give either lo/hi or tolerance, not both")
    idx = seed_indices(volume, seeds, space)
    data = volume.data
    values = data[idx[:, 0], idx[:, 1], idx[:, 2]].astype(float)
    if tolerance is not None:
        if not tolerance >= 0:
            raise ValueError(f"tolerance must be >= 0, got {tolerance}")
        centre = float(values.mean())
        lo, hi = centre - tolerance, centre + tolerance
    lo = -np.inf if lo is None else float(lo)
    hi = np.inf if hi is None else float(hi)
    if lo > hi:
        raise ValueError(f"empty range [{lo}, {hi}]")
    if not np.any((values >= lo) & (values <= hi)):
        raise ValueError(f"no seed has a value in [{lo:g}, {hi:g}]: seed values {np.round(values, 3).tolist()}")
    out = np.zeros(volume.shape, np.uint8)
    n = flood(data, np.float64(lo), np.float64(hi), idx, neighbour_offsets(connectivity), out)
    return mask_like(volume, out.view(np.bool_), range=(lo, hi), voxels=int(n), connectivity=connectivity)

