"""Connected components of masks: label, keep the largest, keep those touching seeds."""

from __future__ import annotations

from typing import Literal

import numpy as np

from ..core import Volume
from ._connectivity import structure
from ._mask import mask_data, mask_like
from ._seeds import seed_indices

__all__ = ["label_components", "keep_largest_component", "keep_components_touching"]


def label_components(mask: Volume, connectivity: int = 26) -> tuple[Volume, int]:
    """Label the connected components of a mask.

    Returns
    -------
    labels : Volume
        int32 on the same grid: 0 for background, 1..n for the components.
    n : int
        Number of components.
    """
    from scipy import ndimage

    labels, n = ndimage.label(mask_data(mask), structure=structure(connectivity))
    return mask.with_data(labels.astype(np.int32, copy=False), modality="SEG", units=""), int(n)


def keep_largest_component(mask: Volume, connectivity: int = 26) -> Volume:
    """The component of the mask with the most voxels (an empty mask stays empty)."""
    from scipy import ndimage

    labels, n = ndimage.label(mask_data(mask), structure=structure(connectivity))
    if n == 0:
        return mask_like(mask, labels > 0)
    sizes = np.bincount(labels.ravel())
    sizes[0] = 0
    return mask_like(mask, labels == np.argmax(sizes), components=int(n))


def keep_components_touching(mask: Volume, seeds, connectivity: int = 26,
                             space: Literal["world", "voxel"] = "world") -> Volume:
    """The components of the mask that contain at least one seed point.

    Seeds are world RAS+ mm or voxel ``(i, j, k)`` (``space``); seeds on background
    select nothing.
    """
    from scipy import ndimage

    idx = seed_indices(mask, seeds, space)
    labels, _ = ndimage.label(mask_data(mask), structure=structure(connectivity))
    keep = np.unique(labels[idx[:, 0], idx[:, 1], idx[:, 2]])
    keep = keep[keep > 0]
    return mask_like(mask, np.isin(labels, keep))
