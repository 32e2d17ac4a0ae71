"""The value range a volume is first shown over: its data range, unless a few bright voxels reach far past the
rest.

A data-relative transfer-function preset (``mr-default``, ``mip-gray``), the first slice window of a scan that is
not a CT and the default isosurface level span the data's values. An MRI often holds a few voxels far brighter
than any tissue: inflow in a vessel, a ringing or motion artefact, a marker, a template's resampling overshoot.
Spanned to its maximum, the tissue then sits low on the ramp: a dark, foggy picture and dark slices. So where the
maximum lies more than :data:`OUTLIER_FACTOR` times as far above the minimum as the :data:`TOP_PERCENTILE`-th
percentile of the voxels above the minimum (the foreground; most of an MRI's voxels are its background), the
range ends at that percentile: the top voxels saturate, as a viewer's automatic window saturates them. Otherwise
(no such outliers) it is the data range, unchanged. A CT keeps its data range (its presets are in Hounsfield
units; its bone and metal are not outliers), and so does a colour volume. The percentile is read on a strided
sample (``_values``).
"""

from __future__ import annotations

import numpy as np

from ._ct import is_ct
from ._values import strided_values

__all__ = ["display_range", "default_iso", "OUTLIER_FACTOR", "TOP_PERCENTILE", "BONE_ISO_HU"]

#: the percentile of the foreground values that the display range may end at
TOP_PERCENTILE = 99.9
#: the maximum is an outlier when it lies this many times farther above the minimum than that percentile
OUTLIER_FACTOR = 1.5
#: a CT's first isosurface: bone (HU)
BONE_ISO_HU = 300.0


def display_range(volume) -> tuple[float, float]:
    """``(lo, hi)``: the data range (``Volume.value_range``), its top cut to the foreground's
    :data:`TOP_PERCENTILE`-th percentile where the maximum is an outlier (module docstring)."""
    lo, hi = volume.value_range()
    if volume.is_color or not hi > lo or is_ct(volume):
        return lo, hi
    v = strided_values(volume)
    v = v[np.isfinite(v) & (v > lo)]
    if v.size == 0:
        return lo, hi
    top = float(np.percentile(v, TOP_PERCENTILE))
    if top > lo and hi - lo > OUTLIER_FACTOR * (top - lo):
        return lo, top
    return lo, hi


def default_iso(volume) -> float:
    """The isosurface level a volume is first shown with: bone (:data:`BONE_ISO_HU`) in a CT, else the middle of
    its display range."""
    if is_ct(volume):
        return BONE_ISO_HU
    lo, hi = display_range(volume)
    return 0.5 * (lo + hi)
