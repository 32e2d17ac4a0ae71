"""``phantom("terraces")``: CT values in coarse steps, so that many samples equal an iso level exactly.

A CT stores whole HU; meshed at a whole level, every sample equal to the level is a grid point the level
passes through. Where its neighbours are on both sides of the level, marching cubes' crossings on its edges all
fall on that point; a file format that joins corners by position (STL) then has collapsed triangles and, where
inside voxels pinch the point from two sides, edges of four triangles (the VMTK aorta rounded to int16
at 300 HU had 18,804 and 50 of them). A real scan has such samples wherever the level crosses it slowly; this
phantom has them everywhere: a smooth random field (white noise through a Gaussian of ``sigma`` voxels, scaled
to unit standard deviation), ``level + step * round(2 * field)`` HU, about a fifth of the samples exactly at
``level``, with saddles at the level between lumps above and below it. Deterministic for a ``seed``.
"""

from __future__ import annotations

import numpy as np

from ..core import Volume
from ._canvas import VoxelGrid

__all__ = ["terraces"]


def terraces(size=None, *, level=300, step=100, sigma=1.5, seed=1, spacing=1.0) -> Volume:
    """Whole-HU terraces around ``level`` (int16, ``size`` voxels per axis, default 24, at ``spacing`` mm);
    ``meta["truth"]``: the level and the fraction of samples equal to it."""
    n = (24,) * 3 if size is None else ((int(size),) * 3 if np.ndim(size) == 0 else tuple(int(s) for s in size))
    if min(n) < 2 or int(level) != level or int(step) != step or step <= 0 or sigma <= 0:
        raise ValueError(f"terraces need sizes >= 2, a whole level and step > 0 and sigma > 0 (got {n}, {level}, "
                         f"{step}, {sigma})")
    from scipy.ndimage import gaussian_filter

    field = gaussian_filter(np.random.default_rng(seed).normal(size=n), sigma, mode="wrap")
    data = (int(level) + int(step) * np.round(2.0 * field / field.std())).astype(np.int16)
    h = np.broadcast_to(np.asarray(spacing, dtype=float), (3,))  # (dz, dy, dx)
    grid = VoxelGrid.centred(np.array(n[::-1]) * h[::-1], n, (0.0, 0.0, 0.0))
    truth = {"kind": "terraces", "level": float(level), "at_level": float(np.mean(data == level))}
    return Volume(data, spacing=grid.spacing, affine=grid.affine, modality="CT", units="HU", name="terraces",
                  meta={"truth": truth})
