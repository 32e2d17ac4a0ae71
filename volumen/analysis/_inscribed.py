"""The distance from inside a lumen to its wall: the radius of the largest sphere centred there that fits.

A lumen mask ``[z, y, x]`` stands for a smooth wall through the half-way points between its inside and
outside voxel centres. Distances to the voxels themselves misread it: to the nearest outside voxel
centre (``scipy.ndimage.distance_transform_edt``) they overstate it by up to half a voxel, to the nearest
outside voxel box they understate it by as much (the staircase's corners poke in where the wall runs
diagonally), and a distance map interpolated between voxels flattens its ridge on the lumen's axis by a
third of a voxel. :class:`WallDistance` draws the wall instead: the mask smoothed by a Gaussian of
:data:`SMOOTH` voxels and cut at one half by marching cubes (``skimage.measure.marching_cubes``, on the
lumen's bounding box), and measures to its vertices (a k-d tree), a vertex about every voxel: to within a
few hundredths of a voxel of the distance to the surface.

The maximum inscribed sphere radius of a cross-section is the largest such distance over the section
(:mod:`._sections`): VMTK's ``MaximumInscribedSphereRadius`` at a point of its centerline, which lies on
the lumen's medial axis, so a centerline drawn half a millimetre off that axis reads the same.
"""

from __future__ import annotations

import numpy as np

__all__ = ["WallDistance", "SMOOTH"]

#: the mask is smoothed by a Gaussian of this many voxels before it is cut at one half
SMOOTH = 1.0


class WallDistance:
    """The distance (mm) from points to the smooth wall of a lumen (bool ``[z, y, x]``, voxel ``spacing``
    ``(dz, dy, dx)`` mm); voxels beyond the array's edge count as outside."""

    def __init__(self, lumen: np.ndarray, spacing):
        from scipy import ndimage
        from scipy.spatial import cKDTree
        from skimage.measure import marching_cubes

        mask = np.asarray(lumen, bool)
        self.spacing = np.asarray(spacing, float)
        zyx = np.argwhere(mask)
        self.tree = None
        if zyx.size == 0:
            return
        lo = np.maximum(zyx.min(axis=0) - 1, 0)
        hi = np.minimum(zyx.max(axis=0) + 2, mask.shape)
        sub = np.pad(mask[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]].astype(np.float32), 2)  # the edge is outside
        smooth = ndimage.gaussian_filter(sub, SMOOTH)
        if smooth.max() <= 0.5:
            return
        verts, _, _, _ = marching_cubes(smooth, 0.5)
        self.tree = cKDTree((verts + lo - 2) * self.spacing)

    def sample(self, coords: np.ndarray) -> np.ndarray:
        """The distance (mm) at voxel coordinates ``coords`` (3, ...) ``[z, y, x]`` of the scan (inside or out)."""
        c = np.asarray(coords, float)
        if self.tree is None:
            return np.zeros(c.shape[1:])
        d, _ = self.tree.query(np.moveaxis(c, 0, -1).reshape(-1, 3) * self.spacing)
        return d.reshape(c.shape[1:])
