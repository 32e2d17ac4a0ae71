"""Neighbourhoods of voxels: 6 (faces), 18 (faces and edges) or 26 (faces, edges, corners)."""

from __future__ import annotations

import numpy as np

__all__ = ["CONNECTIVITIES", "neighbour_offsets", "structure"]

CONNECTIVITIES = (6, 18, 26)


def _check(connectivity: int) -> int:
    if connectivity not in CONNECTIVITIES:
        raise ValueError(f"connectivity must be one of {CONNECTIVITIES}, got {connectivity!r}")
    return int(connectivity)


def structure(connectivity: int = 26) -> np.ndarray:
    """(3, 3, 3) bool neighbourhood for ``scipy.ndimage`` (centre included)."""
    from scipy import ndimage

    rank = {6: 1, 18: 2, 26: 3}[_check(connectivity)]
    return ndimage.generate_binary_structure(3, rank)


def neighbour_offsets(connectivity: int = 26) -> np.ndarray:
    """(k, 3) int64 ``[dz, dy, dx]`` offsets of the neighbours (centre excluded)."""
    rank = {6: 1, 18: 2, 26: 3}[_check(connectivity)]
    d = np.array([(a, b, c) for a in (-1, 0, 1) for b in (-1, 0, 1) for c in (-1, 0, 1)], np.int64)
    n = np.abs(d).sum(axis=1)
    return d[(n >= 1) & (n <= rank)]
