"""Label-aware classification: each sample's structure picks its colour and opacity.

The frame carries the label map ``a.label_map`` (the scan's grid, integer values) and a table
``a.label_lut`` with a row ``(r, g, b, opacity, textured)`` per label value (row 0: the unlabelled
scan, ``r < 0`` meaning the transfer function's own colour; see ``core.LabelLayer.table``).
``s.nlabels`` > 0 turns it on.

Smooth boundaries: the sample's classification is the trilinear blend of the classifications
of the 8 surrounding voxels' labels (``Sampling.interpolation`` nearest: the nearest voxel's)
-- the per-label indicator fields interpolated, without storing them: ``C = sum_i w_i a_i c_i``,
``A = sum_i w_i a_i`` (premultiplied), where a label
with ``textured`` takes ``a_i = opacity * alpha_tf(v)``, else ``a_i = opacity`` (corrected to
the step). A hidden structure (opacity 0) fades out over one voxel instead of a staircase.
"""

from __future__ import annotations

import numpy as np

from ...jit import njit, run_parts
from ._sample import _cell

__all__ = ["classify", "classify_sample", "solid_rows", "label_table", "packed_labels", "label_blocks"]


def packed_labels(data: np.ndarray) -> np.ndarray:
    """The frame's ``lab``: label values (uint8 up to 127, else uint16 up to 32767) with the top bit set on the
    voxels whose cell (the voxel and its +x, +y, +z neighbours, edges repeated) holds one label only, so the
    kernel reads one value inside a structure. Cached per data array (a label map is not changed in place)."""
    key = (id(data), data.shape, data.dtype.str)
    hit = _PACKED.get("key")
    if hit is not None and hit[0] == key and hit[1] is data:
        return hit[2]
    top = int(data.max(initial=0))
    if top > 32767:
        raise ValueError(f"label values up to 32767 are drawn, found {top}")
    dtype, bit = (np.uint8, 128) if top < 128 else (np.uint16, 32768)
    p = np.pad(data, ((0, 1), (0, 1), (0, 1)), mode="edge")
    n0, n1, n2 = data.shape
    uniform = np.ones(data.shape, bool)
    for dk in (0, 1):
        for dj in (0, 1):
            for di in (0, 1):
                if dk or dj or di:
                    uniform &= p[dk:dk + n0, dj:dj + n1, di:di + n2] == data
    out = data.astype(dtype) | (uniform.astype(dtype) * dtype(bit))
    _PACKED["key"] = (key, data, out)
    return out


_PACKED: dict = {}
UNIFORM8, UNIFORM16 = 128, 32768


def solid_rows(llut: np.ndarray) -> np.ndarray:
    """Rows of a label table drawn with an opacity of their own (shown, not textured)."""
    return (llut[:, 3] > 0.0) & (llut[:, 4] == 0.0)


def label_table(layer, ratio: float) -> np.ndarray:
    """The frame's ``llut``: the layer's rows with each solid structure's opacity corrected from the reference
    step to the sampling step (``ratio`` = step / reference step); float32 ``(n, 5)``."""
    t = layer.table().copy()
    solid = t[:, 4] == 0.0
    t[solid, 3] = 1.0 - (1.0 - np.clip(t[solid, 3], 0.0, 1.0)) ** ratio
    return t


@njit(cache=True, fastmath=True, inline="always")
def _add(a, lab, w, idx, acc):
    """``acc`` plus the classification of label value ``lab`` weighted by ``w``."""
    m = min(int(lab) & (UNIFORM16 - 1 if a.label_map.itemsize == 2 else UNIFORM8 - 1), a.label_lut.shape[0] - 1)
    llut = a.label_lut
    al = llut[m, 3] * w
    if llut[m, 4] > 0.0:
        al *= a.lut[idx, 3]
    if llut[m, 0] < 0.0:
        return acc[0] + al * a.lut[idx, 0], acc[1] + al * a.lut[idx, 1], acc[2] + al * a.lut[idx, 2], acc[3] + al
    return acc[0] + al * llut[m, 0], acc[1] + al * llut[m, 1], acc[2] + al * llut[m, 2], acc[3] + al


@njit(cache=True, fastmath=True, inline="always")
def classify_sample(a, s, x, y, z, idx):
    """:func:`classify` for the primary rays (frame settings ``s``): where the transfer function is transparent
    and no shown structure is solid (``s.solid_labels`` false: every row's opacity follows the table's), the sample
    is transparent whatever its labels, and none is read."""
    if not s.solid_labels and a.lut[idx, 3] <= 0.0:
        return 0.0, 0.0, 0.0, 0.0
    return classify(a, x, y, z, idx, s.nearest)


@njit(cache=True, fastmath=True, inline="always")
def classify(a, x, y, z, idx, nearest):
    """Premultiplied ``(r, g, b, alpha)`` of the sample at voxel-index position ``(x, y, z)`` (table index
    ``idx``); the nearest voxel's label alone when ``nearest`` (the raw voxel staircase). In a cell inside one
    structure (flagged by :func:`packed_labels`, the common case) one label and one table row are read.

    ``a`` is any record with the fields ``label_map``, ``label_lut`` and ``lut`` (the frame's
    :class:`._frame.Arrays`, or the light paths' :class:`._medium.Medium`): the primary rays and the light paths
    classify alike."""
    lab = a.label_map
    nz, ny, nx = lab.shape
    zero = (0.0, 0.0, 0.0, 0.0)
    if nearest:
        i = min(max(int(x + 0.5), 0), nx - 1)
        j = min(max(int(y + 0.5), 0), ny - 1)
        k = min(max(int(z + 0.5), 0), nz - 1)
        return _add(a, lab[k, j, i], 1.0, idx, zero)
    l000 = lab[min(max(int(z), 0), nz - 1), min(max(int(y), 0), ny - 1), min(max(int(x), 0), nx - 1)]
    if int(l000) >= (UNIFORM16 if lab.itemsize == 2 else UNIFORM8):  # a cell inside one structure: its corner
        return _add(a, l000, 1.0, idx, zero)
    i0, i1, fx = _cell(x, nx)
    j0, j1, fy = _cell(y, ny)
    k0, k1, fz = _cell(z, nz)
    acc = zero
    for c in range(8):  # corner c: bit 0 -> x, bit 1 -> y, bit 2 -> z (one call site: small kernels compile fast)
        i, wx = (i1, fx) if c & 1 else (i0, 1.0 - fx)
        j, wy = (j1, fy) if c & 2 else (j0, 1.0 - fy)
        k, wz = (k1, fz) if c & 4 else (k0, 1.0 - fz)
        acc = _add(a, lab[k, j, i], wz * wy * wx, idx, acc)
    return acc

@njit(cache=True, nogil=True)
def _solid_blocks(part, parts, lab, solid, block, out):
    """``out[bk, bj, bi]`` = 1 where a voxel within one voxel of the block holds a value whose ``solid`` flag is
    set (values past the table read its last row, as :func:`classify` does), for the block planes of part
    ``part`` of ``parts`` (``volumen.jit.run_parts``)."""
    nz, ny, nx = lab.shape
    gz, gy, gx = out.shape
    mask = UNIFORM16 - 1 if lab.itemsize == 2 else UNIFORM8 - 1
    top = solid.shape[0] - 1
    for bk in range(part * gz // parts, (part + 1) * gz // parts):
        for bj in range(gy):
            for bi in range(gx):
                hit = 0
                for k in range(max(bk * block - 1, 0), min((bk + 1) * block + 1, nz)):
                    for j in range(max(bj * block - 1, 0), min((bj + 1) * block + 1, ny)):
                        for i in range(max(bi * block - 1, 0), min((bi + 1) * block + 1, nx)):
                            if solid[min(int(lab[k, j, i]) & mask, top)]:
                                hit = 1
                                break
                        if hit:
                            break
                    if hit:
                        break
                out[bk, bj, bi] = hit


def label_blocks(lab: np.ndarray, llut: np.ndarray, block: int) -> np.ndarray:
    """uint8 flags per block (``ceil(shape / block)``, ``[z, y, x]``): 1 where a voxel within one voxel of the
    block holds a label drawn with some opacity of its own (a solid structure), for empty-space skipping.
    The last few (label map, table, block) are cached (a frame switching between tables finds its own)."""
    key = (id(lab), llut.tobytes(), int(block))
    cache = _PACKED.setdefault("blocks", {})
    hit = cache.get(key)
    if hit is not None and hit[0] is lab:
        return hit[1]
    shape = tuple(-(-n // block) for n in lab.shape)
    out = np.zeros(shape, np.uint8)
    solid = solid_rows(llut)
    if solid.any():
        run_parts(_solid_blocks, shape[0], lab, solid, int(block), out)
    if len(cache) >= 4:
        cache.pop(next(iter(cache)))
    cache[key] = (lab, out)
    return out
