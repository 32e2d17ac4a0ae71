"""volumen.segment: thresholds, region growing, connected components, morphology (docs/design.md section 1).

Masks are uint8 0/1 :class:`~volumen.core.Volume` objects on the grid of the volume they
come from (``Volume.with_data``); seeds are world RAS+ mm or voxel ``(i, j, k)``.
SciPy and Numba are imported on first use.
"""

from ._bridges import cut_bridges
from ._components import keep_components_touching, keep_largest_component, label_components
from ._connectivity import CONNECTIVITIES, neighbour_offsets
from ._mask import mask_data, mask_like
from ._morphology import ball, binary_close, binary_open, dilate, erode, fill_holes
from ._region_growing import region_grow
from ._seeds import seed_indices
from ._threshold import threshold

__all__ = [
    "threshold",
    "region_grow",
    "seed_indices",
    "label_components",
    "keep_largest_component",
    "keep_components_touching",
    "ball",
    "dilate",
    "erode",
    "binary_open",
    "binary_close",
    "fill_holes",
    "cut_bridges",
    "mask_like",
    "mask_data",
    "CONNECTIVITIES",
    "neighbour_offsets",
]
