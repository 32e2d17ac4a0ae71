"""Label-aware classification: each sample's structure picks its colour and opacity.

The frame carries the label map ``a.lab`` (the scan's grid, integer values) and a table
``a.llut`` with a row ``(r, g, b, opacity, textured)`` per label value (row 0: the unlabelled
scan, ``r < 0`` meaning the transfer function's own colour; see ``core.LabelLayer.table``).
``s.nlab`` > 0 turns it on.

Smooth boundaries: the sample's classification is the trilinear blend of the classifications
of the 8 surrounding voxels' labels (``Sampling.interpolation`` nearest: the nearest voxel's)
-- the per-label indicator fields interpolated, without storing them: ``C = sum_i w_i a_i c_i``,
``A = sum_i w_i a_i`` (premultiplied), where a label
with ``textured`` takes ``a_i = opacity * alpha_tf(v)``, else ``a_i = opacity`` (corrected to
the step). A hidden structure (opacity 0) fades out over one voxel instead of a staircase.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ._sample import _cell

__all__ = ["classify", "label_table"]


def label_table(layer, ratio: float) -> np.ndarray:
    """The frame's ``llut``: the layer's rows with each solid structure's opacity corrected from the reference
    step to the sampling step (``ratio`` = step / reference step); float32 ``(n, 5)``."""
    t = layer.table().copy()
    solid = t[:, 4] == 0.0
    t[solid, 3] = 1.0 - (1.0 - np.clip(t[solid, 3], 0.0, 1.0)) ** ratio
    return t


@njit(cache=True, fastmath=True, inline="always")
def _corner(a, k, j, i, w, idx, acc):
    row = a.llut[min(int(a.lab[k, j, i]), a.llut.shape[0] - 1)]
    al = row[3] * (a.lut[idx, 3] if row[4] > 0.0 else 1.0) * w
    if row[0] < 0.0:
        return acc[0] + al * a.lut[idx, 0], acc[1] + al * a.lut[idx, 1], acc[2] + al * a.lut[idx, 2], acc[3] + al
    return acc[0] + al * row[0], acc[1] + al * row[1], acc[2] + al * row[2], acc[3] + al


@njit(cache=True, fastmath=True, inline="always")
def classify(r, a, t, idx, nearest):
    """Premultiplied ``(r, g, b, alpha)`` of the sample at ray parameter ``t`` (table index ``idx``); the nearest
    voxel's label alone when ``nearest`` (the raw voxel staircase)."""
    nz, ny, nx = a.lab.shape
    if nearest:
        i = min(max(int(r.oi + t * r.di + 0.5), 0), nx - 1)
        j = min(max(int(r.oj + t * r.dj + 0.5), 0), ny - 1)
        k = min(max(int(r.ok + t * r.dk + 0.5), 0), nz - 1)
        return _corner(a, k, j, i, 1.0, idx, (0.0, 0.0, 0.0, 0.0))
    i0, i1, fx = _cell(r.oi + t * r.di, nx)
    j0, j1, fy = _cell(r.oj + t * r.dj, ny)
    k0, k1, fz = _cell(r.ok + t * r.dk, nz)
    acc = (0.0, 0.0, 0.0, 0.0)
    for c in range(2):
        k = k1 if c else k0
        wz = fz if c else 1.0 - fz
        for b in range(2):
            j = j1 if b else j0
            wzy = wz * (fy if b else 1.0 - fy)
            acc = _corner(a, k, j, i0, wzy * (1.0 - fx), idx, acc)
            acc = _corner(a, k, j, i1, wzy * fx, idx, acc)
    return acc



def label_blocks(lab: np.ndarray, llut: np.ndarray, block: int) -> np.ndarray:
    """uint8 flags per block (``ceil(shape / block)``, ``[z, y, x]``): 1 where a voxel within one voxel of the
    block holds a label drawn with some opacity of its own (a solid structure), for empty-space skipping."""
    from scipy import ndimage

    solid = (llut[:, 3] > 0.0) & (llut[:, 4] == 0.0)
    vis = ndimage.maximum_filter(solid[np.minimum(lab, len(llut) - 1)].view(np.uint8), size=3, mode="nearest")
    shape = tuple(-(-n // block) for n in lab.shape)
    padded = np.zeros(tuple(s * block for s in shape), np.uint8)
    padded[: lab.shape[0], : lab.shape[1], : lab.shape[2]] = vis
    return padded.reshape(shape[0], block, shape[1], block, shape[2], block).max(axis=(1, 3, 5))
