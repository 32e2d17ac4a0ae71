"""Tables the kernels read, rebuilt cheaply whenever the transfer function or the step changes.

* 1-D table ``(NLUT, 4)``: r, g, b (straight) and alpha, evenly over the
  volume's value range; for composite rendering alpha is already corrected
  to the step ``ds`` (:func:`volumen.render.optics.correct_opacity`).
* pre-integrated table ``(NPRE, NPRE, 4)`` indexed ``[front, back]``: the
  premultiplied colour and opacity of a ray segment of length ``ds`` along
  which the value goes linearly from ``front`` to ``back`` (Engel, Kraus &
  Ertl 2001), with extinction ``sigma(v) = -ln(1 - a(v)) / ds0`` and colour
  weighted by extinction (no self-attenuation inside the segment).
* block visibility ``uint8`` per block: 1 where some value in the block's
  ``[min, max]`` has non-zero opacity, from prefix sums of the table's
  ``alpha > 0``; turned into skip sides by :func:`~._octants.octant_sides`.
* gradient-opacity table ``(128,)``: factor per magnitude code.
* optical-depth table ``(NLUT,)``: ``-ln(1 - alpha)`` of the uncorrected
  opacity, per reference step (:func:`volumen.render.optics.optical_depth`):
  what light paths (shadows, scattering) accumulate.
"""

from __future__ import annotations

import numpy as np

from ...jit import njit
from ..optics import correct_opacity, optical_depth
from ._octants import octant_sides
from ._precompute import NLUT

__all__ = ["NPRE", "entry_prefix", "color_table", "extinction_table", "preintegrated_table", "block_visibility",
           "iso_visibility", "gradient_table", "coarse_blocks", "ADAPTIVE_ALPHA", "ADAPTIVE_STRIDE"]

#: side of the pre-integrated table
NPRE = 512


@njit(cache=True)
def _correct_column(alpha, ratio, out):
    for i in range(alpha.shape[0]):
        out[i] = correct_opacity(alpha[i], ratio)


def color_table(tf, vmin: float, vmax: float, ratio: float | None) -> np.ndarray:
    """``(NLUT, 4)`` float32 table of ``tf`` over ``[vmin, vmax]``; alpha corrected to ``ratio = ds/ds0`` unless
    None."""
    lut = np.ascontiguousarray(tf.lut(vmin, vmax, NLUT), dtype=np.float32)
    if ratio is not None:
        a = lut[:, 3].astype(np.float64)
        out = np.empty_like(a)
        _correct_column(a, float(ratio), out)
        lut[:, 3] = out
    return lut


@njit(cache=True)
def _depth_column(alpha, out):
    for i in range(alpha.shape[0]):
        out[i] = optical_depth(alpha[i])


def extinction_table(tf, vmin: float, vmax: float) -> np.ndarray:
    """``(NLUT,)`` float32 optical depth per reference step of ``tf``'s opacity over ``[vmin, vmax]``."""
    a = tf.lut(vmin, vmax, NLUT)[:, 3].astype(np.float64)
    out = np.empty_like(a)
    _depth_column(a, out)
    return out.astype(np.float32)


#: optical depth per reference step of an isosurface's inside, for shadows: transmittance e^-30 ~ 1e-13
ISO_DEPTH = 30.0


def iso_extinction_table(u_iso: float) -> np.ndarray:
    """``(NLUT,)`` float32 optical depth per reference step for shadows in isosurface mode: the surface is
    the occluder, so samples at or above the normalized threshold ``u_iso`` are opaque and the rest empty
    (the transfer function's opacity would disagree with the drawn surface near it)."""
    idx = np.arange(NLUT, dtype=np.float64)
    return np.where(idx >= u_iso, ISO_DEPTH, 0.0).astype(np.float32)


def preintegrated_table(tf, vmin: float, vmax: float, ratio: float) -> np.ndarray:
    """``(NPRE, NPRE, 4)`` float32 pre-integrated table for a step of ``ratio = ds / ds0``.

    Entry ``[f, b]`` is for a segment whose normalized value goes from
    ``f * (NLUT-1)/(NPRE-1)`` to ``b * (NLUT-1)/(NPRE-1)``; rgb premultiplied.
    """
    fine = tf.lut(vmin, vmax, NLUT).astype(np.float64)
    a = np.clip(fine[:, 3], 0.0, 1.0 - 1e-7)
    sigma = -np.log1p(-a)  # per reference step
    x = np.arange(NLUT, dtype=np.float64)
    # cumulative integrals over the normalized value (trapezoid)
    def cumint(y):
        c = np.zeros(NLUT)
        c[1:] = np.cumsum(0.5 * (y[1:] + y[:-1]))
        return c

    T = cumint(sigma)
    K = [cumint(sigma * fine[:, c]) for c in range(3)]
    s = np.linspace(0.0, NLUT - 1, NPRE)
    Ts = np.interp(s, x, T)
    Ks = [np.interp(s, x, k) for k in K]
    sig_pt = np.interp(s, x, sigma)
    col_pt = [np.interp(s, x, fine[:, c]) for c in range(3)]
    dv = s[None, :] - s[:, None]  # back - front
    dT = Ts[None, :] - Ts[:, None]
    same = np.abs(dv) < 1e-9
    with np.errstate(divide="ignore", invalid="ignore"):
        mean_sigma = np.where(same, sig_pt[:, None], dT / np.where(same, 1.0, dv))
        alpha = 1.0 - np.exp(-np.maximum(mean_sigma, 0.0) * ratio)
        out = np.empty((NPRE, NPRE, 4), np.float32)
        for c in range(3):
            dK = Ks[c][None, :] - Ks[c][:, None]
            avg = np.where(np.abs(dT) > 1e-12, dK / np.where(np.abs(dT) > 1e-12, dT, 1.0),
                           0.5 * (col_pt[c][:, None] + col_pt[c][None, :]))
            out[..., c] = np.clip(avg, 0.0, 1.0) * alpha
    out[..., 3] = alpha
    return out


def entry_prefix(marked: np.ndarray) -> np.ndarray:
    """int64 ``(len + 1,)``: ``[i]`` how many of the table entries before ``i`` are ``marked``; the marked entries
    in ``[a, b]`` are ``prefix[b + 1] - prefix[a]``."""
    return np.concatenate([[0], np.cumsum(np.asarray(marked, bool))]).astype(np.int64)


def _entries_in_range(marked: np.ndarray, bmin: np.ndarray, bmax: np.ndarray) -> np.ndarray:
    """Per block, how many ``marked`` table entries lie in ``[floor(bmin), ceil(bmax)]`` (a prefix sum), int32; a
    slab of blocks at a time, so the temporaries are a slab's (the whole grid's were 0.3x an int16 volume's bytes)."""
    prefix = entry_prefix(marked)
    bmin, bmax = np.atleast_1d(bmin), np.atleast_1d(bmax)
    out = np.empty(bmin.shape, np.int32)
    for k in range(bmin.shape[0]):
        lo = np.clip(np.floor(bmin[k]).astype(np.int64), 0, NLUT - 1)
        hi = np.clip(np.ceil(bmax[k]).astype(np.int64), 0, NLUT - 1)
        out[k] = prefix[hi + 1] - prefix[lo]
    return out


def block_visibility(lut_alpha: np.ndarray, bmin: np.ndarray, bmax: np.ndarray) -> np.ndarray:
    """uint8 flags per block: 1 if any table entry in ``[floor(bmin), ceil(bmax)]`` has alpha > 0."""
    return (_entries_in_range(lut_alpha > 0, bmin, bmax) > 0).astype(np.uint8)


def iso_visibility(u_iso: float, bmin: np.ndarray, bmax: np.ndarray) -> np.ndarray:
    """uint8 flags per block: 1 where some value reaches the normalized threshold (``bmax >= u_iso``).

    A block entirely above the threshold is not skippable either: the first sample a ray takes in it
    is the hit when the samples before it (at a coarse step) stepped over the crossing block.
    """
    return (bmax >= u_iso).astype(np.uint8)


def gradient_table(tf, gmax: float) -> np.ndarray:
    """``(128,)`` float32: opacity factor of magnitude code ``c`` (``|g| = gmax * (c / 127) ** 2``)."""
    codes = np.arange(128, dtype=np.float64)
    return tf.gradient_factor(gmax * (codes / 127.0) ** 2).astype(np.float32)


#: adaptive sampling (``Sampling.adaptive``): a block is sampled coarsely where every value in its range classifies
#: below this opacity per step ...
ADAPTIVE_ALPHA = 0.1
#: ... with one sample standing for up to this many steps
ADAPTIVE_STRIDE = 4


def faint_blocks(lut_alpha: np.ndarray, bmin: np.ndarray, bmax: np.ndarray) -> np.ndarray:
    """uint8 flags per block: 1 if every table entry in ``[floor(bmin), ceil(bmax)]`` has alpha below
    :data:`ADAPTIVE_ALPHA` (nearly transparent throughout, or empty)."""
    return (_entries_in_range(lut_alpha >= ADAPTIVE_ALPHA, bmin, bmax) == 0).astype(np.uint8)


def coarse_blocks(lut_alpha: np.ndarray, bmin: np.ndarray, bmax: np.ndarray) -> np.ndarray:
    """uint8 ``(8, gz, gy, gx)``: 0 where adaptive sampling keeps the full rate (the block holds a value at or
    above :data:`ADAPTIVE_ALPHA`, or nothing visible: skipping jumps over it); in a block that is visible and
    faint throughout (:func:`faint_blocks`), per octant of ray directions the side in blocks of the largest cube
    of such blocks that starts at it and extends the octant's way (capped at 255): one span of coarse steps for
    a ray of that octant. That is :func:`~._octants.octant_sides` of the blocks that are not coarse."""
    coarse = (faint_blocks(lut_alpha, bmin, bmax) > 0) & (block_visibility(lut_alpha, bmin, bmax) > 0)
    return octant_sides((~coarse).astype(np.uint8))
