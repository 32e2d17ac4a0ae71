"""Masks: 0/1 uint8 Volumes on the grid of the volume they were made from."""

from __future__ import annotations

import numpy as np

from ..core import Volume

__all__ = ["mask_like", "mask_data"]


def mask_like(volume: Volume, data: np.ndarray, **meta) -> Volume:
    """A mask Volume (uint8 0/1, modality ``SEG``, no units) on ``volume``'s grid."""
    out = volume.with_data(np.asarray(data, dtype=bool).view(np.uint8), modality="SEG", units="",
                           meta={"mask_of": volume.name, **meta})
    return out


def mask_data(mask, shape=None) -> np.ndarray:
    """The boolean ``[z, y, x]`` array of a mask Volume or array (a view when possible)."""
    data = mask.data if isinstance(mask, Volume) else np.asarray(mask)
    if data.ndim != 3:
        raise ValueError(f"a mask must be 3-D [z, y, x], got shape {data.shape}")
    if shape is not None and data.shape != tuple(shape):
        raise ValueError(f"mask shape {data.shape} differs from the volume's {tuple(shape)}")
    if data.dtype == np.bool_:
        return data
    if data.dtype == np.uint8 and data.flags.c_contiguous:
        return (data != 0) if data.max(initial=0) > 1 else data.view(np.bool_)
    return data != 0
