"""Seed points: world millimetres or voxel indices -> array indices [z, y, x]."""

from __future__ import annotations

from typing import Literal

import numpy as np

from ..core import Volume

__all__ = ["seed_indices"]

SPACES = ("world", "voxel")


def seed_indices(volume: Volume, seeds, space: Literal["world", "voxel"] = "world") -> np.ndarray:
    """Nearest voxel of each seed as array indices.

    Parameters
    ----------
    volume : Volume
    seeds : (3,) or (n, 3) float
        World RAS+ mm ``(x, y, z)`` when ``space="world"``; voxel indices
        ``(i, j, k)`` = (column, row, slice) when ``space="voxel"``.
    space : {"world", "voxel"}

    Returns
    -------
    (n, 3) int64
        ``[z, y, x]`` index of each seed.

    Raises
    ------
    ValueError
        For an unknown space or a seed outside the volume (named by its position).
    """
    if space not in SPACES:
        raise ValueError(f"space must be one of {SPACES}, got {space!r}")
    pts = np.atleast_2d(np.asarray(seeds, dtype=float))
    if pts.ndim != 2 or pts.shape[1] != 3 or len(pts) == 0:
        raise ValueError(f"seeds must be (3,) or (n, 3) points, got shape {np.shape(seeds)}")
    ijk = volume.world_to_index(pts) if space == "world" else pts
    idx = np.rint(ijk).astype(np.int64)[:, ::-1]  # (i, j, k) -> [z, y, x]
    inside = np.all((idx >= 0) & (idx < np.array(volume.shape)), axis=1)
    if not inside.all():
        bad = pts[~inside][0]
        raise ValueError(f"seed {tuple(np.round(bad, 3))} ({space}) lies outside the volume {volume.shape} [z, y, x]")
    return idx
