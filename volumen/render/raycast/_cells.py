"""Pre-classified cells: one bit per cell of the volume saying whether a sample in it can be visible.

A cell is the box between 8 neighbouring voxels ``[k..k+1, j..j+1, i..i+1]`` (clamped at the far borders). A
trilinear or nearest sample in it takes a value between the corners' smallest and largest. Where the frame's
table gives every entry a value of that range can read zero opacity, no sample in the cell adds anything to a
post-classified composite ray (nor to its depth), and the marching loop passes over the sample without
reconstructing its value (``_march``). That is exact: the pictures do not change, only the samples taken.

Empty-space skipping decides per block of the skipping grid (4 voxels a side by default); a block straddling
bone and soft tissue must be sampled, and in an opaque preset most of its samples are transparent. The cells
decide per voxel cell inside such blocks, one byte read for eight cells.

The bits are built per transfer function, from which table entries are visible, in one pass over the volume,
packed eight cells to a byte along x: ``bits[k, j, i >> 3] >> (i & 7) & 1``, a sixteenth of an int16 volume's
size. ``_pack`` builds them from the second frame with the same visible entries on and keeps them while the
camera moves. Not for pre-integration (a segment needs the sample before it), labels (their own
classification), the B-spline (its value can leave the corners' range) or the path tracer.
"""

from __future__ import annotations

import numpy as np

from ...jit import njit, run_parts
from ._tables import entry_prefix

__all__ = ["cell_bits", "cell_visible", "cell_open", "NO_CELLS"]

#: the placeholder of a frame that reads no cell bits
NO_CELLS = np.zeros((1, 1, 1), np.uint8)

#: table units by which a cell's range is widened on both sides: a sample (int16 for every volume:
#: ``_precompute.int16_samples``), computed in float64 with rounding error just past its corners' range, still
#: finds its table entry inside the range checked.
_MARGIN = 1e-6


@njit(cache=True, nogil=True)
def _bits_kernel(part, parts, u, u0, ufac, prefix, bits):
    """Planes of part ``part`` of ``parts`` (``volumen.jit.run_parts``). ``lr`` / ``hr``: the extremes of the
    four voxels ``[k..k+1, j..j+1, i]`` along the row, each read once for the two cells that share them."""
    nz, ny, nx = u.shape
    top = prefix.shape[0] - 2
    lr = np.empty(nx, np.float64)
    hr = np.empty(nx, np.float64)
    for k in range(part * nz // parts, (part + 1) * nz // parts):
        k1 = min(k + 1, nz - 1)
        for j in range(ny):
            j1 = min(j + 1, ny - 1)
            for i in range(nx):
                a, b, c, d = u[k, j, i], u[k, j1, i], u[k1, j, i], u[k1, j1, i]
                lr[i] = min(min(a, b), min(c, d))
                hr[i] = max(max(a, b), max(c, d))
            for w in range(bits.shape[2]):
                byte = 0
                for i in range(8 * w, min(8 * w + 8, nx)):
                    i1 = min(i + 1, nx - 1)
                    lo = (min(lr[i], lr[i1]) - u0) * ufac + 0.5 - _MARGIN  # the table entries the samples read
                    hi = (max(hr[i], hr[i1]) - u0) * ufac + 0.5 + _MARGIN
                    e0 = min(max(int(lo), 0), top)
                    e1 = min(max(int(hi), 0), top)
                    if prefix[e1 + 1] > prefix[e0]:
                        byte |= 1 << (i - 8 * w)
                bits[k, j, w] = byte


def cell_bits(u: np.ndarray, u0: float, ufac: float, lut_alpha: np.ndarray) -> np.ndarray:
    """uint8 ``(nz, ny, ceil(nx / 8))``: bit ``i & 7`` of ``[k, j, i >> 3]`` set where a sample in cell
    ``(k, j, i)`` of the samples ``u`` (table units ``(u - u0) * ufac``, read at ``int(v + 0.5)``) can have an
    opacity ``lut_alpha > 0``."""
    nz, ny, nx = u.shape
    prefix = entry_prefix(np.asarray(lut_alpha) > 0)
    bits = np.empty((nz, ny, (nx + 7) // 8), np.uint8)
    run_parts(_bits_kernel, nz, u, float(u0), float(ufac), prefix, bits)
    return bits


@njit(cache=True, fastmath=True, inline="always")
def cell_open(cells, vol, x, y, z):
    """Whether a sample of ``vol`` at index position (x, y, z) can have an opacity above zero (``cells``: the bits
    of :func:`cell_bits`; positions clamped as the samplers clamp them)."""
    nz, ny, nx = vol.shape
    i = min(max(int(x), 0), nx - 1)
    j = min(max(int(y), 0), ny - 1)
    k = min(max(int(z), 0), nz - 1)
    return (cells[k, j, np.uintp(i) >> 3] >> (i & 7)) & 1 != 0


@njit(cache=True, fastmath=True, inline="always")
def cell_visible(a, x, y, z):
    """Whether a sample at index position (x, y, z) can be visible (``a.cells``)."""
    return cell_open(a.cells, a.vol, x, y, z)
