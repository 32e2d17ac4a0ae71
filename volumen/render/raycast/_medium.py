"""The medium that light paths cross: optical depth per reference step at a point, and a scattering event's colour.

Shadow rays (:mod:`._shadow`), the illumination-volume sweeps (:mod:`._lightsweep`) and the path tracer's
tracking (:mod:`._pathtrace`) all read the medium through :func:`depth_at`, so they see what the primary
rays draw:

* without labels, the transfer function's optical depth per reference step ``extinction`` of the trilinear value
  (docs/design.md section 3);
* with a label map (``nlabels > 0``), the label-aware classification of the primary rays
  (:func:`._labelled.classify`: per-structure colour and opacity, hidden structures transparent), turned
  from the opacity ``A`` of one sample step into optical depth per reference step:
  ``tau = -ln(1 - A) * lscale``, ``lscale = ds0 / (ds * extinction_scale)`` (the tables the primary rays read
  are corrected to the step ``ds`` and scaled by ``extinction_scale``; the unlabelled scan's rows give back
  ``extinction`` exactly, up to rounding).
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from ...jit import njit
from ..optics import MAX_OPACITY, optical_depth
from ._bspline import reconstruct
from ._labelled import classify
from ._pieces import ScanOnly, Trilinear, WithLabels, labelled

__all__ = ["Medium", "frame_medium", "depth_at", "event_color", "depth_bound", "label_scale"]


class Medium(NamedTuple):
    """What a light path reads (the volume's axes may be permuted, ``label_map``'s alike: a lattice sweep). The
    fields it shares with the frame's records (``_frame.Arrays``, ``_frame.Settings``) have their names."""

    vol: Any             #: samples [z, y, x], read as ``_bspline.reconstruct`` does with ``recon``
    extinction: Any      #: optical depth per reference step of each table entry (NLUT,)
    sample_offset: float  #: samples -> table units: ``(v - sample_offset) * sample_scale``
    sample_scale: float
    label_map: Any       #: label map on ``vol``'s grid (``_labelled.packed_labels``), (1, 1, 1) when unused
    label_lut: Any       #: per label value (r, g, b, opacity, textured) (n, 5)
    lut: Any             #: the primary rays' colour / opacity table (NLUT, 4), opacity per step ``ds``
    lscale: float        #: ``ds0 / (ds * extinction_scale)``: optical depth of a step's opacity -> per reference step
    nlabels: int         #: label-aware classification when > 0
    recon: Any = Trilinear()  #: reconstruction tag (``_pieces``: ``Settings.recon``)
    labels: Any = ScanOnly()  #: label tag (``_pieces``: ``Settings.labels``): ``WithLabels()`` exactly when nlabels > 0


def label_scale(ds: float, ds0: float, kext: float) -> float:
    """:attr:`Medium.lscale` of a frame."""
    return float(ds0) / (float(ds) * float(kext))


@njit(cache=True, fastmath=True, inline="always")
def frame_medium(a, s):
    """The :class:`Medium` of a packed frame (``a``, ``s``: ``_frame.Arrays``, ``_frame.Settings``)."""
    return Medium(a.vol, a.extinction, s.sample_offset, s.sample_scale, a.label_map, a.label_lut, a.lut,
                  s.ds0 / (s.ds * s.extinction_scale), s.nlabels, s.recon, s.labels)


@njit(cache=True, fastmath=True, _nrt=False)
def _classified(m, x, y, z, idx):
    """:func:`._labelled.classify` for a light path, compiled once and called, not inlined at every sampling
    site (shadow rays, sweeps, tracking): only label scenes reach it, and kernels compile faster without it."""
    return classify(m, x, y, z, idx, False)


@njit(cache=True, fastmath=True, inline="always")
def depth_at(m, x, y, z):
    """``(optical depth per reference step, table index)`` at voxel-index position ``(x, y, z)`` (trilinear, or the
    B-spline: ``m.recon``)."""
    v = reconstruct(m.recon, m.vol, m.sample_offset, m.sample_scale, x, y, z, False)
    idx = min(max(int(v + 0.5), 0), m.extinction.shape[0] - 1)
    if not labelled(m.labels):
        return m.extinction[idx], idx
    return optical_depth(_classified(m, x, y, z, idx)[3]) * m.lscale, idx


@njit(cache=True, fastmath=True, inline="always")
def event_color(m, x, y, z, idx):
    """Straight colour of a scattering event at ``(x, y, z)`` (table index ``idx``): the transfer function's,
    or the classified sample's (its premultiplied colour over its opacity) with labels."""
    if not labelled(m.labels):
        return m.lut[idx, 0], m.lut[idx, 1], m.lut[idx, 2]
    cr, cg, cb, al = _classified(m, x, y, z, idx)
    if al <= 0.0:
        return 0.0, 0.0, 0.0
    return cr / al, cg / al, cb / al


@labelled.register(ScanOnly)
@njit(cache=True, inline="always")
def _scan_only():
    return False


@labelled.register(WithLabels)
@njit(cache=True, inline="always")
def _with_labels():
    return True


def depth_bound(sig: np.ndarray, llut: np.ndarray, lscale: float, nlab: int) -> float:
    """The largest optical depth per reference step :func:`depth_at` returns (the majorant of tracking).

    A classified opacity is a convex blend of its corners' rows: a solid row's is its opacity, a textured
    row's its opacity times the table's, whose optical depth is at most ``sig``'s (equal for opacity 1: a
    label map drawn with the scan's own transfer function traces the same random paths as the scan alone).
    """
    if nlab <= 0:
        return float(sig.max())
    op = np.clip(llut[:, 3].astype(np.float64), 0.0, MAX_OPACITY)
    textured = (llut[:, 4] > 0.0) & (op > 0.0)
    solid = -np.log1p(-op[llut[:, 4] == 0.0]) * lscale
    return max(float(sig.max()) if textured.any() else 0.0, float(solid.max(initial=0.0)))
