"""The subject of a volume: the part a picture drawn with the defaults shows, as the box the camera frames.

A scan's box holds air or background around the patient, and often much of it: a CT's field of view is a
cylinder with the table at its foot, a cropped angiogram is long in one direction and thin in the others.
Framed by the box, the anatomy came out small. The subject is the voxels above the level where the default
transfer function starts to show something: :data:`SUBJECT_HU` in a CT (air and the lung's inside stay out; skin,
fat and the table are in), the transparent bottom of ``mr-default`` (:data:`MR_CLEAR` of the display range)
in any other scan. They are read on a strided sample (about ``SAMPLE`` voxels), and each axis's bounds leave out
:data:`TAIL` of the subject's voxels at either end, so a few bright noise voxels in the background do not widen
the box; the bounds then grow by one stride, within which the true edge lies.
"""

from __future__ import annotations

import numpy as np

from ._ct import hu_offset
from ._display import LABEL_VALUES, MR_CLEAR, display_range
from ._values import SAMPLE, strided_values
from ._volume import is_chunked

__all__ = ["subject_level", "subject_corners", "subject_floor", "subject_values", "SUBJECT_HU", "TAIL",
           "FLOOR_PERCENTILE"]

#: a CT's subject starts here (HU): above air and the inside of the lung, below fat and skin
SUBJECT_HU = -500.0
#: the share of the subject's sampled voxels each axis's bounds may leave out at either end
TAIL = 0.001
#: the percentile of the subject's values where its darkest tissue is taken to start (:func:`subject_floor`)
FLOOR_PERCENTILE = 5.0


def subject_level(volume) -> float:
    """The value above which a voxel belongs to the subject: :data:`SUBJECT_HU` on a CT's stored values
    (``hu_offset``), the top of ``mr-default``'s transparent bottom otherwise (:data:`MR_CLEAR` of
    ``display_range``), the minimum of a label map (every label is the subject)."""
    offset = hu_offset(volume)
    if offset is not None:
        return SUBJECT_HU + offset
    lo, hi = display_range(volume)
    return lo + MR_CLEAR * (hi - lo)


def subject_values(volume) -> np.ndarray:
    """The subject's values: those of the strided sample (``_values``) above :func:`subject_level`, flat."""
    s = strided_values(volume)
    with np.errstate(invalid="ignore"):
        return s[s > subject_level(volume)]


def subject_floor(volume) -> float | None:
    """The :data:`FLOOR_PERCENTILE`-th percentile of the subject's values (:func:`subject_values`): where its
    darkest tissue starts; None where no sampled voxel is above the level."""
    inside = subject_values(volume)
    return float(np.percentile(inside, FLOOR_PERCENTILE)) if inside.size else None


def _stride(shape) -> int:
    return max(1, int(round((float(np.prod(shape)) / SAMPLE) ** (1.0 / 3.0))))


def _bounds(inside: np.ndarray, axis: int, step: int, n: int) -> tuple[int, int]:
    """Voxel indices ``(first, last)`` of the subject along array ``axis`` (of ``n`` voxels), from the strided
    mask ``inside`` (every ``step``-th voxel), less :data:`TAIL` of it at either end and grown by one stride."""
    others = tuple(a for a in range(3) if a != axis)
    counts = np.cumsum(inside.sum(axis=others))
    total = counts[-1]
    first = int(np.searchsorted(counts, TAIL * total, side="right"))
    last = int(np.searchsorted(counts, (1.0 - TAIL) * total, side="left"))
    return max(0, (first - 1) * step), min(n - 1, (last + 1) * step)


def subject_corners(volume) -> np.ndarray:
    """(8, 3) world RAS+ mm: the corners of the subject's box (voxel centres, along the voxel axes); the
    volume's own corners (``Volume.corners``) for a colour or chunked volume, a slab of one or two samples, or
    one with no voxel above :func:`subject_level`."""
    data = volume.data
    if volume.is_color or is_chunked(data) or min(data.shape[:3]) < 3:
        return volume.corners()
    step = _stride(data.shape[:3])
    sample = np.asarray(data[::step, ::step, ::step])
    ints = np.issubdtype(sample.dtype, np.integer)
    if ints and np.unique(sample).size <= LABEL_VALUES and hu_offset(volume) is None:
        inside = sample > sample.min()
    else:
        with np.errstate(invalid="ignore"):
            inside = sample > subject_level(volume)
    if not inside.any():
        return volume.corners()
    (z0, z1), (y0, y1), (x0, x1) = (_bounds(inside, a, step, n) for a, n in enumerate(data.shape[:3]))
    ijk = np.array([[i, j, k] for k in (z0, z1) for j in (y0, y1) for i in (x0, x1)], float)
    return volume.index_to_world(ijk)
