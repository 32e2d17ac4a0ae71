"""Colour volumes: the voxel's own RGB as the emission colour of a sample.

A colour volume (``Volume.is_color``: ``data`` (nz, ny, nx, 3)) is classified
by its luminance (``Volume.luminance``; 8-bit channels as int16 fixed point,
``LUMA_STEPS`` steps per unit, see :func:`luminance_samples`): the transfer function's opacity,
the gradients (normals), the skipping grids, shadows and the projections
(MIP / MinIP / average show luminance) all read the luminance copy
``Arrays.vol``. Only the emission colour differs: where ``Settings.color``
is set, a composite sample's colour (and a path-traced event's albedo) is
the trilinearly (or nearest-) interpolated voxel RGB, ``Arrays.rgb``
(nz, ny, nx, 3) uint8 scaled to [0, 1], instead of the table's colour.
Scalar volumes carry a (1, 1, 1, 3) placeholder and ``color = False``.
"""

from __future__ import annotations

import numpy as np

from ...jit import njit
from ._sample import _cell

__all__ = ["rgb8", "luminance_samples", "sample_rgb", "emission", "NO_RGB", "LUMA_STEPS"]

#: ``Arrays.rgb`` of a scalar volume
NO_RGB = np.zeros((1, 1, 1, 3), np.uint8)


#: fixed-point steps per unit of an 8-bit colour volume's luminance samples (255 x 128 = 32640 fits int16)
LUMA_STEPS = 128


def luminance_samples(volume) -> tuple[np.ndarray, int]:
    """``(samples, steps)``: the luminance a colour volume is classified by, ``steps`` samples per data unit.

    8-bit channels: ``rint(luminance x LUMA_STEPS)`` as int16, at most 1/256 of a level off the exact luma
    (the channels themselves resolve 1 level), sampled in place by the same int16 kernels as CT's at half the
    memory of a float32 copy. Other types: ``Volume.luminance()`` (float32), 1 step per unit, which
    ``_precompute.int16_samples`` quantizes to int16 as any float volume.
    """
    if volume.data.dtype == np.uint8:
        return np.rint(volume.luminance() * np.float32(LUMA_STEPS)).astype(np.int16), LUMA_STEPS
    return volume.luminance(), 1


def rgb8(data: np.ndarray) -> np.ndarray:
    """The colour samples as the kernels read them: uint8 data itself (C-contiguous), other types scaled from
    their finite ``[min, max]`` over all channels to 0..255."""
    if data.dtype == np.uint8:
        return np.ascontiguousarray(data)
    d = np.nan_to_num(data.astype(np.float32), nan=0.0, posinf=0.0, neginf=0.0)
    lo, hi = float(min(d.min(), 0.0)), float(d.max())
    f = 255.0 / (hi - lo) if hi > lo else 0.0
    return np.ascontiguousarray(np.clip(np.rint((d - lo) * f), 0, 255).astype(np.uint8))


@njit(cache=True, fastmath=True, inline="always")
def sample_rgb(rgb, x, y, z, nearest):
    """RGB in [0, 1] of ``rgb[z, y, x, :]`` at index position (x, y, z): trilinear, or nearest."""
    nz, ny, nx = rgb.shape[0], rgb.shape[1], rgb.shape[2]
    if nearest:
        i = min(max(int(x + 0.5), 0), nx - 1)
        j = min(max(int(y + 0.5), 0), ny - 1)
        k = min(max(int(z + 0.5), 0), nz - 1)
        return rgb[k, j, i, 0] / 255.0, rgb[k, j, i, 1] / 255.0, rgb[k, j, i, 2] / 255.0
    i0, i1, fx = _cell(x, nx)
    j0, j1, fy = _cell(y, ny)
    k0, k1, fz = _cell(z, nz)
    cr = cg = cb = 0.0
    for c in range(2):  # z
        k = k1 if c else k0
        wz = fz if c else 1.0 - fz
        for b in range(2):  # y
            j = j1 if b else j0
            wzy = wz * (fy if b else 1.0 - fy)
            w0 = wzy * (1.0 - fx)
            w1 = wzy * fx
            cr += w0 * rgb[k, j, i0, 0] + w1 * rgb[k, j, i1, 0]
            cg += w0 * rgb[k, j, i0, 1] + w1 * rgb[k, j, i1, 1]
            cb += w0 * rgb[k, j, i0, 2] + w1 * rgb[k, j, i1, 2]
    return cr / 255.0, cg / 255.0, cb / 255.0


@njit(cache=True, fastmath=True, inline="always")
def emission(a, s, x, y, z, c):
    """Premultiplied sample ``c = (r, g, b, alpha)`` with its colour replaced by the voxel RGB at index position
    (x, y, z) when the frame is of a colour volume (``s.color``); ``c`` itself otherwise."""
    if not s.color:
        return c
    al = c[3]
    cr, cg, cb = sample_rgb(a.rgb, x, y, z, s.nearest)
    return cr * al, cg * al, cb * al, al
