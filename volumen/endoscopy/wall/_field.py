"""The wall of a lumen as a scalar field with a level: what collisions and the unfolded view stop at.

Three ways to say where the wall is:

* a CT value threshold (:meth:`WallField.from_threshold`): for an air-filled
  lumen (colon, airway) the wall is where the data rises to the threshold
  (e.g. -500 HU); for a contrast-filled lumen (vessels) where it falls below
  it (the field is then the negated data);
* the transfer function's opacity (:meth:`WallField.from_transfer`): the wall
  is where the opacity per reference step reaches a level (what you see);
* a lumen mask (:meth:`WallField.from_mask`): the wall is where the trilinear
  interpolation of "not lumen" reaches 0.5, half-way between voxel centres.

The field is sampled trilinearly, in voxel-index space, like the renderer.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

__all__ = ["WallField"]


@dataclass(frozen=True, eq=False)
class WallField:
    """A scalar field ``[z, y, x]`` whose values ``>= level`` are wall.

    Attributes
    ----------
    volume : Volume
        The geometry (affine, spacing) the field lives on.
    field : (nz, ny, nx) array
        Samples (the volume's own data when no conversion is needed: not copied).
    level : float
        Wall threshold in the field's units.
    kind : str
        How it was built (``"threshold"``, ``"transfer"``, ``"mask"``), for reports.
    """

    volume: object
    field: np.ndarray
    level: float
    kind: str = "threshold"

    @property
    def geometry(self) -> np.ndarray:
        """Packed float64 geometry for the kernels (world -> index affine and index box)."""
        from ...core import Clipping
        from ...render.raycast import pack_geometry

        g = self.__dict__.get("_geo")
        if g is None:
            g = pack_geometry(self.volume, Clipping())
            object.__setattr__(self, "_geo", g)
        return g

    @property
    def step(self) -> float:
        """Default marching step: half the smallest voxel spacing, mm."""
        return 0.5 * float(min(self.volume.spacing))

    @classmethod
    def from_threshold(cls, volume, threshold: float = -500.0,
                       lumen: Literal["below", "above"] = "below") -> WallField:
        """Wall where the data crosses ``threshold`` (data units, e.g. HU).

        Parameters
        ----------
        volume : Volume
        threshold : float, data units
            -500 HU suits air-filled lumens (air -1000, soft tissue 0..60).
        lumen : {"below", "above"}
            ``below``: the lumen is darker than the wall (air); ``above``: the
            lumen is brighter (contrast-filled vessels, ~300 HU, threshold ~150).
        """
        if lumen not in ("below", "above"):
            raise ValueError(f"lumen must be 'below' or 'above', got {lumen!r}")
        if not np.isfinite(threshold):
            raise ValueError(f"threshold must be finite, got {threshold}")
        data = volume.data
        if lumen == "below":
            return cls(volume, data, float(threshold), "threshold")
        return cls(volume, np.negative(data, dtype=np.float32), -float(threshold), "threshold")

    @classmethod
    def from_transfer(cls, volume, transfer, opacity: float = 0.5) -> WallField:
        """Wall where the transfer function's opacity (per reference step) reaches ``opacity`` (0..1)."""
        if not 0.0 < opacity <= 1.0:
            raise ValueError(f"opacity must be in (0, 1], got {opacity}")
        a = np.asarray(transfer.opacity, float)
        field = np.interp(volume.data, a[:, 0], a[:, 1]).astype(np.float32)
        return cls(volume, field, float(opacity), "transfer")

    @classmethod
    def from_mask(cls, volume, mask) -> WallField:
        """Wall outside a boolean lumen ``mask [z, y, x]`` (same shape as the volume)."""
        m = np.asarray(mask)
        if m.shape != volume.shape:
            raise ValueError(f"mask shape {m.shape} differs from the volume's {volume.shape}")
        return cls(volume, (~m.astype(bool)).astype(np.float32), 0.5, "mask")
