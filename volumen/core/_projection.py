"""The grey window a projection of a scan that is not a CT is first shown with, read from the projection's values.

A maximum intensity projection shows the brightest voxel along each ray, so its pixels hold the top of a scan's
values, not their spread. Windowed over the voxels (from the subject's darkest tissue to the display range's
top), an MRI's MIP filled the top of the grey ramp: milky (``ch2better``: mean grey 0.70), and where many rays
meet the brightest tissue (``mr_head``'s scalp, a uniform object) it was white and flat, its texture lost.

So the window is read from projections: the maxima along each voxel axis of the strided sample (``_values``;
three orthographic MIPs, the anatomical views' own). Over their subject (pixels above ``subject_level``) the grey
ramp starts at their :data:`LOW_PERCENTILE`-th percentile and reaches a shade below white (``1 - SHOULDER``) at its
knee, their :data:`HIGH_PERCENTILE`-th percentile or Tukey's far-out fence where lower; past the knee it rises
slowly to white at their maximum (a filmic shoulder): the brightest tissue keeps its texture, the far outliers
(the few voxels of inflow or artefact an MRI holds, which each light a pixel of every projection) show bright
without taking the tissue's grey, and only the brightest pixel saturates, whatever the scan's units.

Not for a CT (its MIP is read in HU over the data range: bone and contrast at the top), a colour, chunked or
label volume, or one whose projections show no subject: :func:`projection_window` gives None and the caller keeps
its own range.
"""

from __future__ import annotations

import numpy as np

from ._ct import hu_offset
from ._display import LABEL_VALUES
from ._subject import subject_level
from ._values import SAMPLE
from ._volume import is_chunked

__all__ = ["projection_window", "LOW_PERCENTILE", "HIGH_PERCENTILE", "FENCE", "SHOULDER", "HEADROOM"]

#: the percentile of the projections' subject pixels where the ramp starts (black)
LOW_PERCENTILE = 2.0
#: the percentile of the projections' subject pixels where the ramp reaches the grey 1 - SHOULDER (its knee) ...
HIGH_PERCENTILE = 99.5
#: ... or Tukey's far-out fence (this many interquartile ranges above the upper quartile), where lower: far
#: outliers (inflow, artefacts: a few voxels, but each lights a pixel of every projection) lie past it
FENCE = 3.0
#: the grey left between the knee and white: from the knee the ramp rises to white at the projections' maximum
#: (at least HEADROOM of the window past the knee), so the brightest tissue keeps its texture and outliers show
#: bright without saturating
SHOULDER = 0.05
HEADROOM = 0.05


def _projected(volume) -> np.ndarray | None:
    """The subject's pixels of the three axis projections (maxima along z, y and x of the strided sample), flat;
    None where the volume is not one this module windows (module docstring)."""
    data = volume.data
    if volume.is_color or is_chunked(data) or min(data.shape[:3]) < 2:
        return None
    step = max(1, int(round((data.size / SAMPLE) ** (1.0 / 3.0))))
    sample = np.asarray(data[::step, ::step, ::step])
    labels = np.issubdtype(sample.dtype, np.integer) and np.unique(sample).size <= LABEL_VALUES
    if labels and hu_offset(volume) is None:  # a CT of a few values (an analytic phantom) is not a label map
        return None
    sample = np.where(np.isfinite(sample), sample, -np.inf) if sample.dtype.kind == "f" else sample
    level = subject_level(volume)
    pixels = np.concatenate([sample.max(axis=a).ravel() for a in range(3)]).astype(np.float64)
    inside = pixels[pixels > level]
    return inside if inside.size else None


def projection_window(volume) -> tuple[float, float, float] | None:
    """``(black, knee, white)``: the values a maximum intensity projection of ``volume`` is first drawn black, at
    the grey ``1 - SHOULDER`` and white (module docstring), or None where the caller's own range stands."""
    pixels = _projected(volume)
    if pixels is None:
        return None
    low, q1, q3, high = (float(v) for v in np.percentile(pixels, [LOW_PERCENTILE, 25.0, 75.0, HIGH_PERCENTILE]))
    knee = min(high, q3 + FENCE * (q3 - q1))
    if not knee > low:  # a uniform subject: its projection is one value, drawn a shade below white
        low = float(subject_level(volume))
    if not knee > low:
        return None
    return low, knee, max(float(pixels.max()), knee + HEADROOM * (knee - low))
