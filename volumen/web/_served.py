"""The scan as the page gets it: fitted to the client's 3-D texture size and a memory budget, sent as 16 bits.

The page holds the volume as one 3-D ``R16F`` texture (half floats: filtered linearly by every WebGL2
implementation, unlike 16-bit integers or 32-bit floats). :class:`ServedVolume` decides what it gets:

* **fitting**: a volume with an axis past the client's ``MAX_3D_TEXTURE_SIZE``, or more voxels than the
  memory budget holds at 2 bytes each, is resampled onto a coarser grid (box-filtered first, so it is not
  aliased) covering the same voxel-centre box; :attr:`ServedVolume.notices` says so. The served
  :class:`~volumen.core.Volume` is then *the* volume of the viewer: every frame is packed from it by the
  ray caster's own code, so the CPU renders of it are the pictures the page must equal.
* **encoding**: integer data spanning at most 4097 values is stored as ``value - centre``, which half floats
  hold exactly (integers up to 2048 in magnitude); anything else (floats, wider ranges) as its table units
  (``raycast.pack_frame``'s ``(u - u0) * ufac``, 0..4095) minus 2048, within a quarter of a table entry
  below 1024 units from the middle and half of one above (a notice says so). The shader turns texels back
  into table units with ``u_vol_map`` (``(texel + map[0]) * map[1]``).

Nothing served says who the patient is: :meth:`ServedVolume.info` lists geometry, modality, units and the
value histogram, never ``Volume.name`` or ``Volume.meta`` (which holds the source path).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from volumen.render.raycast._cache import prepare

__all__ = ["ServedVolume", "fit_volume", "encode_half", "DEFAULT_BUDGET_MB", "DEFAULT_MAX_3D", "HALF_EXACT"]

#: default memory budget of the volume texture on the client (MiB; 2 bytes per voxel)
DEFAULT_BUDGET_MB = 256
#: 3-D texture size assumed until the page says its own (WebGL2's common MAX_3D_TEXTURE_SIZE)
DEFAULT_MAX_3D = 2048
#: integers of magnitude up to this are exact in a half float
HALF_EXACT = 2048


def fit_volume(volume, max_3d: int, budget_bytes: int):
    """``(volume, factor)``: ``volume`` itself (factor 1.0), or resampled on a grid ``factor`` times coarser
    along every axis of more than two samples (a slab's thin axis keeps its samples) so no axis is past
    ``max_3d`` voxels and 2 bytes per voxel fit ``budget_bytes``.

    The data is box-filtered over the new spacing before it is resampled (trilinear) onto the new grid,
    whose first voxel centre is the old one's (``Volume.resample``).
    """
    from scipy import ndimage

    shape = np.array(volume.shape, float)
    coarse = shape > 2
    factor = max(1.0, float((shape.max() - 1) / (max_3d - 1)) if shape.max() > max_3d else 1.0,
                 float((2.0 * shape.prod() / budget_bytes) ** (1 / 3)))
    if factor <= 1.0:
        return volume, 1.0
    while True:  # the resampled grid rounds its sizes; grow the factor until it fits
        n = np.where(coarse, np.floor((shape - 1) / factor + 1e-6) + 1, shape)
        if n.max() <= max_3d and 2.0 * n.prod() <= budget_bytes:
            break
        factor *= 1.01
    size = np.where(coarse, max(1, int(round(factor))), 1)
    data = volume.data
    smooth = ndimage.uniform_filter(data.astype(np.float32), size=tuple(size) + (1,) * (data.ndim - 3),
                                     mode="nearest") if size.max() > 1 else data
    if data.dtype.kind in "iu":
        smooth = np.rint(smooth).astype(data.dtype)
    out = volume.with_data(smooth).resample(tuple(np.where(coarse, factor, 1.0) * volume.spacing))
    return out, factor


def in_memory(volume, max_3d: int, budget_bytes: int):
    """``volume`` with its samples in memory: a chunked one (OME-Zarr, read lazily) read from the finest pyramid
    level (``volumen.io.open_levels``) whose grid fits ``max_3d`` voxels a side and 2 bytes a voxel in
    ``budget_bytes``, else its coarsest; :func:`fit_volume` coarsens it the rest of the way."""
    from ..core import is_chunked
    from ..io import load, open_levels

    if not is_chunked(volume.data):
        return volume
    level, path = int(volume.meta.get("level", 0)), volume.meta.get("source")
    if path is not None:
        shapes = [np.array(lv.shape, float) for lv in open_levels(path)[0]]
        fits = [n for n in range(level, len(shapes))
                if shapes[n].max() <= max_3d and 2.0 * shapes[n].prod() <= budget_bytes]
        pick = fits[0] if fits else len(shapes) - 1
        if pick != level:
            volume = load(path, level=pick)
    return volume.with_data(np.asarray(volume.data))


def encode_half(u: np.ndarray, u0: float, ufac: float) -> tuple[np.ndarray, tuple[float, float], bool]:
    """``(texels float16, (add, mul), exact)``: the samples ``u`` as half floats with
    ``table units = (texel + add) * mul``; ``exact`` when no sample was rounded."""
    if u.dtype.kind in "iu":
        lo, hi = int(u.min()), int(u.max())
        if hi - lo <= 2 * HALF_EXACT:
            centre = (lo + hi) // 2
            texels = (u.astype(np.int32) - centre).astype(np.float16)
            return texels, (float(centre - u0), float(ufac)), True
    table = (u.astype(np.float32) - np.float32(u0)) * np.float32(ufac)
    return (table - np.float32(HALF_EXACT)).astype(np.float16), (float(HALF_EXACT), 1.0), False


@dataclass
class ServedVolume:
    """The volume the page draws, fitted to ``max_3d`` and ``budget_mb`` (see the module's docstring).

    Parameters
    ----------
    source : Volume
        The volume that was opened.
    max_3d : int
        The client's ``MAX_3D_TEXTURE_SIZE``.
    budget_mb : float
        Memory budget of the volume texture, MiB.
    """

    source: object
    max_3d: int = DEFAULT_MAX_3D
    budget_mb: float = DEFAULT_BUDGET_MB
    notices: list = field(default_factory=list)

    def __post_init__(self):
        if self.source.is_color:
            raise ValueError("the browser viewer draws scalar volumes; this one holds colours")
        budget = int(self.budget_mb * 2 ** 20)
        self.volume, self.factor = fit_volume(in_memory(self.source, int(self.max_3d), budget).slab(),
                                              int(self.max_3d), budget)
        if self.factor > 1.0:
            z, y, x = self.source.shape
            nz, ny, nx = self.volume.shape
            self.notices.append(f"volume resampled from {x} x {y} x {z} to {nx} x {ny} x {nz} voxels (x, y, z) "
                                f"to fit a 3-D texture of at most {self.max_3d} per axis and "
                                f"{self.budget_mb:g} MiB")

    @cached_property
    def encoded(self) -> tuple[np.ndarray, tuple[float, float], bool]:
        """:func:`encode_half` of the volume's samples as the ray caster prepares them."""

        prep = prepare(self.volume)
        texels, vol_map, exact = encode_half(prep.u, prep.u0, prep.ufac)
        if not exact:
            self.notices.append("volume sent as 16-bit half floats of its transfer-function table position: "
                                "within half a table entry (1/8190 of the value range)")
        return texels, vol_map, exact

    def info(self) -> dict:
        """What the page is told about the volume: geometry, modality, units, values (``value_range``, which its
        sliders span, and the histogram: over the renderers' table range, ``core.table_range``, not out to a fill
        or to far outliers), the slices' first window (``core.default_window``). No name, no source."""
        from ..core import default_window, table_range

        v = self.volume
        lo, hi = table_range(v)
        window = default_window(v)
        counts, edges = v.histogram(128, range=(lo, hi))
        return {"shape": list(v.shape), "spacing": list(v.spacing), "affine": np.asarray(v.affine).tolist(),
                "center": np.asarray(v.center).tolist(), "diagonal": float(v.diagonal),
                "modality": str(v.modality), "units": str(v.units), "value_range": [float(lo), float(hi)],
                "histogram": {"counts": counts.tolist(), "edges": edges.tolist()},
                "window": {"level": float(window.level), "width": float(window.width)},
                "source_shape": list(self.source.shape), "factor": self.factor}
