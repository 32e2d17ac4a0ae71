"""The wall a flythrough draws: the data held to a lumen mask, or the mask's own smoothed boundary.

Drawing the wall as an isosurface of the raw data at the wall threshold shows
whatever crosses that value first: through a bronchus wall thinned by partial
volume the lung behind it, through a segmentation's aorta wall the lung a few
millimetres beyond. :class:`LumenWall` makes the field that is drawn (and
collided with, and unfolded) from the lumen mask (grown, or a segmentation) and
the :class:`LumenEstimate`, on the mask's box (plus a margin), in the scan's own
units so the estimate's threshold and transfer function apply unchanged. With
``s`` the signed distance (mm, < 0 inside) of each voxel centre to the mask's
boundary (half a voxel at the voxels either side of it) and ``h`` the largest voxel
spacing:

* **data held to the mask** (the data separates lumen and wall): the two layers of
  voxels that straddle the boundary (``|s| < 3 h / 4``) keep the data, so the drawn
  wall is the data's own partial-volume edge where the data agrees with the mask;
  deeper inside, voxels take the lumen's value (no noise speck stands in the
  lumen); farther outside, they keep the data where it is on the wall's side of the
  threshold and take the wall's value elsewhere (no lung, no neighbouring lumen
  shows through). Where the data disagrees with the mask, the crossing lies between
  a kept voxel half a voxel from the boundary and a held one at most a voxel and a
  half from it, half-way when the kept one is fully on the other side: within a
  voxel of the mask's boundary either way. Tagged fluid in an air lumen is cleansed: deep inside it is air like
  the rest; near the wall its values between the wall's and the fluid's are mapped
  linearly onto those between the wall's and the air's, so the wall under the fluid is
  drawn where the fluid's own partial-volume edge is;
* **the mask's shape** (the data does not separate them): a ramp from the lumen's
  value to the wall's across one voxel of the mask's signed distance smoothed by a
  Gaussian of one voxel: the isosurface at the threshold is the mask's smoothed boundary.

The mask travels with a saved flight (packed bits, zlib, base64), so the flight
replays every frame on the scan alone.
"""

from __future__ import annotations

import base64
import zlib
from dataclasses import dataclass

import numpy as np

from ._point_estimate import LumenEstimate

__all__ = ["LumenWall", "signed_distance"]

#: voxels of data kept round the mask's box, beyond the band: the renderer's gradient and trilinear reach
MARGIN = 4


def signed_distance(mask: np.ndarray, spacing) -> np.ndarray:
    """Signed distance (mm, float32, < 0 inside) from each voxel centre to the boundary of ``mask``, taken
    half-way between the centres inside and out (Euclidean distance transforms with the spacing)."""
    from scipy import ndimage

    sp = tuple(float(s) for s in spacing)
    half = 0.5 * min(sp)
    inside = ndimage.distance_transform_edt(mask, sampling=sp)
    outside = ndimage.distance_transform_edt(~mask, sampling=sp)
    return np.where(mask, half - inside, outside - half).astype(np.float32)


def _box(mask: np.ndarray, pad: int) -> tuple[slice, ...]:
    from ._grow import _bbox

    return _bbox(mask, pad)


@dataclass(frozen=True, eq=False)
class LumenWall:
    """A lumen and the estimate of its values: makes the field drawn as the wall (see the module docstring).

    Attributes
    ----------
    mask : (nz, ny, nx) bool
        The lumen, on the scan's grid.
    estimate : LumenEstimate
    shape_only : bool
        The data does not separate lumen and wall: draw the mask's smoothed boundary.
    note : str
        One line for the user on how the lumen was chosen (the two ends' lumens disagreed), else ``""``.
    """

    mask: np.ndarray
    estimate: LumenEstimate
    shape_only: bool = False
    note: str = ""

    def volume(self, volume):
        """The field to draw, a :class:`~volumen.core.Volume` on the mask's box (plus a margin), float32 in the
        scan's units: isosurface at ``estimate.threshold``, the lumen on the estimate's side."""
        if self.mask.shape != volume.shape:
            raise ValueError(f"the lumen mask's grid {self.mask.shape} differs from the scan's {volume.shape}")
        box = _box(self.mask, MARGIN + 2)
        sub = self.mask[box]
        s = signed_distance(sub, volume.spacing)
        out = self._shape(s, volume.spacing) if self.shape_only else self._held(sub, s, volume.data[box],
                                                                              volume.spacing)
        return volume.crop(*box).with_data(out, name=f"{volume.name or 'scan'} (lumen wall)")

    def _shape(self, s: np.ndarray, spacing) -> np.ndarray:
        from scipy import ndimage

        e = self.estimate
        sigma = 1.0  # voxel
        smooth = ndimage.gaussian_filter(s, sigma, mode="nearest")
        ramp = np.clip(0.5 + smooth / float(min(spacing)), 0.0, 1.0)
        return (e.lumen + (e.wall - e.lumen) * ramp).astype(np.float32)

    def _held(self, sub: np.ndarray, s: np.ndarray, data, spacing) -> np.ndarray:
        from scipy import ndimage

        e = self.estimate
        h = 0.75 * float(max(spacing))  # the band's half-width (see the module docstring)
        out = np.array(data, np.float32)
        if e.tag is not None:  # cleanse: the fluid-wall edge mapped onto an air-wall edge, near the fluid only
            fluid = ndimage.binary_dilation(sub & (out > 0.5 * (e.wall + e.tag)), iterations=2)
            # the fluid's uneven tagging and noise, scaled up by the mapping, would roughen the wall drawn under
            # it: its edge is read through a Gaussian of half a voxel (what the rays' smoothing does too)
            calm = ndimage.gaussian_filter(out, 0.5, mode="nearest")
            ramp = fluid & (calm > e.wall)
            out[ramp] = e.wall + (calm[ramp] - e.wall) * (e.lumen - e.wall) / (e.tag - e.wall)
        out[s <= -h] = e.lumen
        far = s >= h
        lumen_like = e.sign * out < e.sign * e.threshold
        out[far & lumen_like] = e.wall
        return out

    # -- JSON ---------------------------------------------------------------
    def to_dict(self) -> dict:
        """``{"estimate", "shape_only", "shape", "box", "bits"}``: the mask packed in its box (zlib, base64)."""
        box = _box(self.mask, 0)
        bits = np.packbits(self.mask[box].ravel())
        return {"estimate": self.estimate.to_dict(), "shape_only": bool(self.shape_only),
                "shape": list(self.mask.shape), "box": [[s.start, s.stop] for s in box],
                "bits": base64.b64encode(zlib.compress(bits.tobytes(), 9)).decode("ascii")}

    @classmethod
    def from_dict(cls, d: dict, shape=None) -> LumenWall:
        """Inverse of :meth:`to_dict`; ``shape`` (the scan's) must match the saved one when given."""
        extra = set(d) - {"estimate", "shape_only", "shape", "box", "bits"}
        if extra:
            raise ValueError(f"unknown lumen fields {sorted(extra)}")
        saved = tuple(int(n) for n in d["shape"])
        if shape is not None and tuple(shape) != saved:
            raise ValueError(f"the flight's lumen is on a grid {saved}, the scan's is {tuple(shape)}")
        box = tuple(slice(int(a), int(b)) for a, b in d["box"])
        size = int(np.prod([s.stop - s.start for s in box]))
        bits = np.frombuffer(zlib.decompress(base64.b64decode(d["bits"])), np.uint8)
        mask = np.zeros(saved, bool)
        mask[box] = np.unpackbits(bits, count=size).astype(bool).reshape([s.stop - s.start for s in box])
        return cls(mask, LumenEstimate.from_dict(d["estimate"]), bool(d.get("shape_only", False)))
