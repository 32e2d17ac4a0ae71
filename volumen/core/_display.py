"""The value range an MRI is first shown over: its data range, unless a few voxels reach far past the rest.

The data-relative transfer function ``mr-default``, the first slice window of a scan that is not a CT and the
default isosurface level span the data's values. An MRI often holds a few voxels far brighter than any tissue:
inflow in a vessel, a ringing or motion artefact, a marker, a template's resampling overshoot. Spanned to its
maximum, the tissue then sits low on the ramp: a dark, foggy picture and dark slices. So where the maximum lies
more than :data:`OUTLIER_FACTOR` times as far above the minimum (the background, which most of an MRI's voxels
are) as the :data:`TOP_PERCENTILE`-th percentile of the voxels above it, the range ends at that percentile: the
top voxels saturate, as a viewer's automatic window saturates them. Otherwise it is the data range, unchanged.

Kept at the data range, where the brightest few voxels are the finding or the cut cannot be read well:

* a CT (its presets are in Hounsfield units; bone and metal are not outliers), a colour volume;
* a PET or SPECT (a small hot lesion is the finding), a segmentation or dose;
* a label map (integers, at most :data:`LABEL_VALUES` distinct values in the sample): a rare label is a label;
* a chunked (out-of-core) volume: its sample is three planes, which can miss a bright region the maximum sees
  (its bottom is cut as below: a fill around the field of view is in each of the three axial planes);
* the projections' ``mip-gray`` (an angiogram's MIP is its brightest voxels: ``_transfer.fitted_preset``).

The low end is cut the same way where the minimum is a fill value, not the background: a resampler or a
registration writes the voxels outside the scan's field of view as one value far below any the scanner gave
(-1000, -1e6, the lowest float). Spanned from it, the background sits high on every ramp and the field of view
is drawn as an opaque, milky cylinder: a wall. So where the minimum is negative, held by at least
:data:`FILL_SHARE` of the voxels (a region, where the minimum of noise is one voxel) and lies more than
:data:`FLOOR_GAP` of the range below the :data:`TOP_PERCENTILE`-th percentile from the bottom of the voxels above
it, the range starts at that percentile; the fill voxels classify as the transfer function's low end
(transparent). An MRI's background is never negative: its minimum is 0 or its noise floor, so a range that
starts there, or at a negative noise floor, is kept.

The percentile is read on a strided sample (``_values``).

The renderers' tables (:func:`table_range`) span the data range too, but stop short of such outliers where
they lie very far out: where the maximum lies more than :data:`REACH` display ranges past the minimum (an MRI
written as floats whose few outliers are thousands of times brighter than its tissue), a table of 4,096 entries
spread over it gave the tissue one entry, and every transfer function drew it black. There the table ends at
:data:`REACH` display ranges, so the display range has at least 1/16 of it, and the voxels past that end are
clamped to it: they classify as the transfer function's value there (its brightest, for one that ends below) and
a MIP reads them as that value. Below, the table starts where the display range does (past a fill cut off there
is only the fill), and a CT's no lower than :data:`CT_FLOOR_HU` (a float CT whose fill is -1e6 gave its whole
range to the fill, one entry to 250 HU); the voxels under that start are clamped to it.
"""

from __future__ import annotations

import numpy as np

from ._ct import hu_offset
from ._values import strided_values
from ._volume import is_chunked

__all__ = ["display_range", "table_range", "drawable_range", "default_iso", "OUTLIER_FACTOR", "TOP_PERCENTILE",
           "LABEL_VALUES", "BONE_ISO_HU", "REACH", "FLOOR_GAP", "FILL_SHARE", "CT_FLOOR_HU", "MR_CLEAR"]

#: the percentile of the foreground values that the display range may end at
TOP_PERCENTILE = 99.9
#: the maximum is an outlier when it lies this many times farther above the minimum than that percentile
OUTLIER_FACTOR = 1.5
#: integer data with at most this many distinct values in the sample is taken for a label map
LABEL_VALUES = 64
#: a CT's first isosurface: bone (HU)
BONE_ISO_HU = 300.0
#: modalities whose brightest voxels are the finding (or that are not images of tissue)
_KEEP_TOP = ("PT", "NM", "SEG", "RTDOSE")
#: how many display ranges past the minimum a renderer's table reaches at most (:func:`table_range`)
REACH = 16.0
#: the share of the display range at its bottom that ``mr-default`` leaves transparent (an MRI's background)
MR_CLEAR = 0.1
#: a negative minimum is a fill value where the voxels above it start more than this share of the range above it
#: (half of the transparent bottom of ``mr-default``, :data:`MR_CLEAR`: a background lifted past it turns milky) ...
FLOOR_GAP = 0.05
#: ... and at least this share of the sampled voxels hold it (a region; the minimum of noise is one voxel)
FILL_SHARE = 0.001
#: a CT's table starts no lower than this (HU): int16, which every DICOM CT is stored in, reaches no lower
CT_FLOOR_HU = -32768.0


def display_range(volume, data_range: tuple[float, float] | None = None) -> tuple[float, float]:
    """``(lo, hi)``: the data range (``Volume.value_range``), its bottom cut where the minimum is a fill value and
    its top cut to the foreground's :data:`TOP_PERCENTILE`-th percentile where the maximum is an outlier (module
    docstring). ``data_range``: ``volume.value_range()`` where the caller has it (a pass over the data less)."""
    lo, hi = volume.value_range() if data_range is None else data_range
    chunked, keep = is_chunked(volume.data), str(volume.modality or "").upper() in _KEEP_TOP
    if volume.is_color or not hi > lo or keep or (chunked and not lo < 0.0) or hu_offset(volume) is not None:
        return lo, hi
    s = strided_values(volume)
    if np.issubdtype(s.dtype, np.integer) and np.unique(s).size <= LABEL_VALUES:
        return lo, hi
    s = s[np.isfinite(s)]
    v = s[s > lo]
    if v.size == 0:
        return lo, hi
    top = float(np.percentile(v, TOP_PERCENTILE))
    if lo < 0.0 and np.count_nonzero(s == lo) >= FILL_SHARE * s.size:
        bottom = float(np.percentile(v, 100.0 - TOP_PERCENTILE))
        if bottom - lo > FLOOR_GAP * (top - lo):
            lo = bottom
    if top > lo and hi - lo > OUTLIER_FACTOR * (top - lo) and not chunked:
        return lo, top
    return lo, hi


def table_range(volume, data_range: tuple[float, float] | None = None) -> tuple[float, float]:
    """``(lo, hi)``: the value range a renderer's transfer-function table spans (the ray caster's samples and
    table, the texture slicer's): the data range (``data_range``, else ``volume.value_range()``), its top cut to
    :data:`REACH` display ranges past the display range's bottom, its bottom to the display range's (a fill cut
    off), and a CT's to :data:`CT_FLOOR_HU` (module docstring); the values past ``lo`` and ``hi`` are clamped to
    them."""
    lo, hi = volume.value_range() if data_range is None else data_range
    bottom, top = display_range(volume, (lo, hi))
    start = bottom  # past a fill cut off, nothing but the fill: its jump would also steepen the gradients
    offset = hu_offset(volume)
    if offset is not None:
        start = max(start, offset + CT_FLOOR_HU)
    return start, min(hi, bottom + REACH * (top - bottom))


def drawable_range(lo: float, hi: float) -> tuple[float, float]:
    """A table's range as a renderer can divide by it: ``(0, 1)`` where no value is finite, ``hi`` one unit past
    ``lo`` where the data are flat."""
    if not np.isfinite(lo):
        return 0.0, 1.0
    return float(lo), float(hi) if hi > lo else float(lo) + 1.0


def default_iso(volume) -> float:
    """The isosurface level a volume is first shown with: bone (:data:`BONE_ISO_HU`, on the stored values:
    ``hu_offset``) in a CT, else the middle of its display range."""
    offset = hu_offset(volume)
    if offset is not None:
        return BONE_ISO_HU + offset
    lo, hi = display_range(volume)
    return 0.5 * (lo + hi)
