"""Where a slice view's pixels are in the world (plain numpy, no Qt).

The slice views show :func:`volumen.core.slice_at` pictures of the canonical
(RAS-ordered) volume in radiological orientation: axial with the patient's
right on the left and anterior at the top, coronal with right on the left and
superior at the top, sagittal with anterior on the left and superior at the
top. Display pixel ``(col, row)`` covers ``[col, col+1) x [row, row+1)``;
its centre is ``(col + 0.5, row + 0.5)``.
"""

from __future__ import annotations

import numpy as np

from ..core import PLANES, Volume, slice_at

__all__ = ["SliceGeometry", "DISPLAY_AXES"]

#: plane -> (world axis along display columns, world axis along display rows, world axis of the normal)
DISPLAY_AXES = {"axial": (0, 1, 2), "coronal": (0, 2, 1), "sagittal": (1, 2, 0)}


class SliceGeometry:
    """Mapping between display pixels of one plane and world RAS+ mm.

    Parameters
    ----------
    canonical : Volume
        The volume in canonical RAS voxel order (``volumen.core.canonical``).
    plane : {"axial", "coronal", "sagittal"}
    """

    def __init__(self, canonical: Volume, plane: str):
        if plane not in PLANES:
            raise ValueError(f"plane must be one of {PLANES}, got {plane!r}")
        self.volume = canonical
        self.plane = plane
        nz, ny, nx = canonical.shape
        dz, dy, dx = canonical.spacing
        # voxel axis (0=i, 1=j, 2=k) shown along columns and rows, and the normal's voxel axis
        self._col_axis, self._row_axis, self.normal_axis = DISPLAY_AXES[plane]
        n_ijk = (nx, ny, nz)
        sp_ijk = (dx, dy, dz)
        self.cols, self.rows = n_ijk[self._col_axis], n_ijk[self._row_axis]
        self.col_mm, self.row_mm = sp_ijk[self._col_axis], sp_ijk[self._row_axis]
        self.n_slices = n_ijk[self.normal_axis]

    # display col grows toward -i (axial, coronal) or -j (sagittal); display row grows toward -j or -k
    def index_of(self, world) -> int:
        """The slice index (along the plane's normal, canonical voxels) nearest ``world``, clamped."""
        ijk = self.volume.world_to_index(np.asarray(world, float))
        return int(np.clip(np.rint(ijk[self.normal_axis]), 0, self.n_slices - 1))

    def world_to_display(self, world) -> np.ndarray:
        """World points ``(..., 3)`` -> continuous display ``(..., 2)`` = (col, row) in pixels."""
        ijk = self.volume.world_to_index(np.asarray(world, float))
        col = self.cols - 1 - ijk[..., self._col_axis] + 0.5
        row = self.rows - 1 - ijk[..., self._row_axis] + 0.5
        return np.stack([col, row], axis=-1)

    def display_to_world(self, col: float, row: float, index: int | float) -> np.ndarray:
        """Display ``(col, row)`` (continuous pixels) on slice ``index`` -> world (3,) mm."""
        ijk = np.zeros(3)
        ijk[self._col_axis] = self.cols - 1 - (col - 0.5)
        ijk[self._row_axis] = self.rows - 1 - (row - 0.5)
        ijk[self.normal_axis] = index
        return self.volume.index_to_world(ijk)

    def distance_to_slice(self, world, index: int) -> np.ndarray:
        """Distance (in voxels along the normal) of world points ``(..., 3)`` from slice ``index``."""
        ijk = self.volume.world_to_index(np.asarray(world, float))
        return np.abs(ijk[..., self.normal_axis] - index)

    def image(self, index: int, volume: Volume | None = None) -> np.ndarray:
        """The display slice ``(rows, cols)`` of ``volume`` (default: this geometry's volume, same grid)."""
        v = self.volume if volume is None else volume
        img, _ = slice_at(v, self.plane, index=index, canonical_volume=v)
        return img
