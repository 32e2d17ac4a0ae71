"""A scan as a resampler or a registration writes it: floats, with the voxels outside the field of view one fill
value far below any the scanner gave.

Resampling onto another grid, or registering to a template, leaves voxels that no source voxel covers; tools fill
them with a value of their choosing (-1000, -1024, -1e6, the lowest float). In an MRI that value lies far below its
background (0 or a low noise floor), and defaults spanned from the data's minimum lifted the background high on
every ramp: ``mr-default`` drew the field of view as an opaque, milky cylinder, and a CT's table gave its whole
range to the fill (``core._display``). :func:`fill_outside_field` makes that failure class out of any scalar
phantom: the data as float32, every voxel outside the field-of-view cylinder (around z, :data:`FIELD` of the
width) set to ``fill``.
"""

from __future__ import annotations

import numpy as np

from ..core import Volume

__all__ = ["fill_outside_field", "FIELD"]

#: the field of view's radius as a share of the volume's width along x (a scanner's reconstruction circle)
FIELD = 0.45


def fill_outside_field(volume: Volume, fill: float = -1e6) -> Volume:
    """``volume`` as float32, its voxels outside the field-of-view cylinder (axis z, radius :data:`FIELD` of the
    width along x, in voxels) set to ``fill``; modality, units, name and ``meta`` kept."""
    data = np.array(volume.data, np.float32)
    _, ny, nx = data.shape
    y, x = np.mgrid[:ny, :nx]
    data[:, (x - (nx - 1) / 2) ** 2 + (y - (ny - 1) / 2) ** 2 > (FIELD * nx) ** 2] = np.float32(fill)
    return Volume(data, spacing=volume.spacing, affine=volume.affine, modality=volume.modality, units=volume.units,
                  name=volume.name, meta=dict(volume.meta))
