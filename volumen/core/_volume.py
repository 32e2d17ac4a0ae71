"""The Volume: a 3-D scalar field with its geometry in patient space.

Conventions (docs/design.md section 2):

* ``data`` is a C-contiguous numpy array indexed ``[z, y, x]`` (slice, row, column);
* ``spacing`` is ``(dz, dy, dx)`` in millimetres, the same order as the array;
* ``affine`` is a 4x4 matrix taking the homogeneous voxel index
  ``(i, j, k, 1) = (column, row, slice, 1)`` to world RAS+ millimetres.

Voxel ``(i, j, k)`` is the *centre* of a sample; the world bounding box of a
volume is the box of its voxel centres (index 0 .. n-1 on each axis), which is
also the domain trilinear interpolation and the ray caster work on.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ._repr import picture

__all__ = ["Volume", "axis_codes", "is_chunked", "LUMA_WEIGHTS"]

#: Rec. 601 luma weights of (R, G, B): the grey value of a colour sample.
LUMA_WEIGHTS = (0.299, 0.587, 0.114)

_AXIS_NAMES = (("L", "R"), ("P", "A"), ("I", "S"))


def axis_codes(affine: np.ndarray) -> str:
    """Three letters naming where voxel axes i, j, k point in RAS+ space.

    ``"RAS"`` means i grows toward the patient's Right, j toward Anterior and k
    toward Superior (nibabel's ``aff2axcodes``). For an oblique affine each axis
    is named after the world axis it is closest to.
    """
    m = np.asarray(affine, dtype=float)[:3, :3]
    codes = []
    used: set[int] = set()
    # greedy on the largest absolute cosine, so two voxel axes never get one letter
    cos = np.abs(m) / np.maximum(np.linalg.norm(m, axis=0, keepdims=True), 1e-30)
    order = np.argsort(-cos.max(axis=0))
    picked = [0, 0, 0]
    for col in order:
        ranked = np.argsort(-cos[:, col])
        row = next(int(r) for r in ranked if int(r) not in used)
        used.add(row)
        picked[col] = row
    for col in range(3):
        row = picked[col]
        codes.append(_AXIS_NAMES[row][1 if m[row, col] > 0 else 0])
    return "".join(codes)


#: a volume at most this fraction as thick along one voxel axis as along the next thinnest is a slab
#: (:attr:`Volume.thin_axis`)
SLAB = 0.25


def slab_grid(data, affine: np.ndarray):
    """``(data, affine)`` of a grid whose axes with one sample (array axes z, y, x) hold it twice, half a spacing
    either side of it (``data`` itself where no axis has one sample): the slab a single slice stands for."""
    affine = np.array(affine, dtype=float)
    for axis in (a for a, n in enumerate(np.shape(data)[:3]) if n == 1):
        data = np.repeat(data, 2, axis=axis)
        affine[:3, 3] -= affine[:3, 2 - axis] / 2  # voxel axis k, j, i: back by half a spacing
    return data, affine


def _default_affine(spacing) -> np.ndarray:
    dz, dy, dx = (float(s) for s in spacing)
    return np.diag([dx, dy, dz, 1.0])


def is_chunked(data) -> bool:
    """Whether ``data`` is a lazy chunked array (``volumen.io``'s ``ChunkedArray``): kept as it is by a Volume,
    read chunk by chunk (NumPy-style indexing returns arrays, basic slices and transposes lazy views); it also
    answers ``chunks``, ``chunk_ranges`` (stored per-chunk minima and maxima, or None) and ``cached(max_bytes)``
    (a view read through a bounded chunk cache, and the cache): what ``volumen.render`` draws it out of core with."""
    return bool(getattr(type(data), "__volumen_chunked__", False))


@dataclass(eq=False)
class Volume:
    """A scalar or colour volume in physical units and patient (RAS+) space.

    Parameters
    ----------
    data : (nz, ny, nx) or (nz, ny, nx, 3) array
        Samples indexed ``[z, y, x]``; kept C-contiguous (copied only if it is not).
        A lazy chunked array (``is_chunked``, e.g. an OME-Zarr level) is kept
        as it is: slices read only the chunks they need. Samples stored in the
        other byte order (big-endian files) are converted to this machine's.
        A trailing axis of 3 holds colour (R, G, B; channel last): see ``is_color``.
    spacing : (3,) float, mm, or None
        ``(dz, dy, dx)``. Must agree with the column lengths of ``affine``; None (the
        default) takes them from ``affine``, or 1 mm each without one.
    affine : (4, 4) float, optional
        Voxel ``(i, j, k, 1)`` -> world RAS+ mm. Default: axis-aligned RAS with
        the given spacing and voxel (0, 0, 0) at the origin.
    modality : str
        DICOM-style modality code (``"CT"``, ``"MR"``, ``"OT"``...).
    units : str
        Physical units of the values (``"HU"`` for CT), ``""`` when unknown.
    name : str
        A short label for displays (never patient identity).
    meta : dict
        Free-form facts about the source: ``warnings`` (list of str),
        ``source`` (path), format details. Never holds patient identity.
    """

    data: np.ndarray
    spacing: tuple[float, float, float] | None = None
    affine: np.ndarray | None = None
    modality: str = "OT"
    units: str = ""
    name: str = ""
    meta: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        data = self.data if is_chunked(self.data) else np.asarray(self.data)
        if not (data.ndim == 3 or (data.ndim == 4 and data.shape[3] == 3)):
            raise ValueError(f"Volume data must be 3-D [z, y, x] or colour [z, y, x, 3], got shape {data.shape}")
        if min(data.shape) < 1:
            raise ValueError(f"Volume data has an empty axis: shape {data.shape}")
        if data.dtype == np.bool_:
            data = data.view(np.uint8)
        if not (is_chunked(data) or data.dtype.isnative):  # big-endian samples (a DICOM file's, a raw file's)
            data = data.astype(data.dtype.newbyteorder("="))
        self.data = data if is_chunked(data) else np.ascontiguousarray(data)
        aff = None if self.affine is None else np.array(self.affine, dtype=float)
        if aff is not None:
            if aff.shape != (4, 4) or not np.all(np.isfinite(aff)):
                raise ValueError("affine must be a finite 4x4 matrix")
            if abs(np.linalg.det(aff[:3, :3])) < 1e-12:
                raise ValueError("affine is singular")
        col_len = None if aff is None else np.linalg.norm(aff[:3, :3], axis=0)[::-1]  # |k|, |j|, |i| = dz, dy, dx
        given = self.spacing if self.spacing is not None else (1.0, 1.0, 1.0) if aff is None else col_len
        spacing = tuple(float(s) for s in np.asarray(given, dtype=float).ravel())
        if len(spacing) != 3 or not all(np.isfinite(spacing)) or min(spacing) <= 0:
            raise ValueError(f"spacing must be three positive mm values (dz, dy, dx), got {self.spacing}")
        if col_len is not None and not np.allclose(col_len, spacing, rtol=1e-4, atol=1e-6):
            lengths = ", ".join(f"{v:.6g}" for v in col_len)
            raise ValueError(f"spacing (dz, dy, dx) = ({', '.join(f'{v:.6g}' for v in spacing)}) mm disagrees with "
                             f"the affine's column lengths ({lengths}) mm; leave spacing out to take the affine's")
        self.spacing = spacing
        self.affine = _default_affine(spacing) if aff is None else aff
        self.meta = dict(self.meta)
        # each volume owns its warnings (derived volumes copy meta shallowly: large truth arrays are shared)
        self.meta["warnings"] = list(self.meta.get("warnings", []))

    # -- shape and geometry -------------------------------------------------
    @property
    def shape(self) -> tuple[int, int, int]:
        """``(nz, ny, nx)`` (the grid; a colour volume's channel axis is not part of it)."""
        return self.data.shape[:3]  # type: ignore[return-value]

    @property
    def is_color(self) -> bool:
        """True when ``data`` is ``(nz, ny, nx, 3)``: R, G, B per voxel, channel last."""
        return self.data.ndim == 4

    @property
    def dtype(self) -> np.dtype:
        return self.data.dtype

    @property
    def direction(self) -> np.ndarray:
        """(3, 3) unit column vectors: world directions of voxel axes i, j, k."""
        m = self.affine[:3, :3]
        return m / np.linalg.norm(m, axis=0, keepdims=True)

    @property
    def origin(self) -> np.ndarray:
        """World RAS+ mm of voxel (0, 0, 0)."""
        return self.affine[:3, 3].copy()

    @property
    def orientation(self) -> str:
        """Axis codes of voxel axes (i, j, k), e.g. ``"RAS"`` or ``"LPS"``."""
        return axis_codes(self.affine)

    @property
    def is_oblique(self) -> bool:
        """True when a voxel axis is not parallel to a world axis (tolerance 1e-4)."""
        d = np.abs(self.direction)
        return bool(np.any((d > 1e-4) & (d < 1 - 1e-4)))

    def index_to_world(self, ijk) -> np.ndarray:
        """Voxel indices ``(..., 3)`` as (i, j, k) = (column, row, slice) -> world RAS+ mm ``(..., 3)``."""
        ijk = np.asarray(ijk, dtype=float)
        return ijk @ self.affine[:3, :3].T + self.affine[:3, 3]

    def world_to_index(self, xyz) -> np.ndarray:
        """World RAS+ mm ``(..., 3)`` -> fractional voxel indices (i, j, k) ``(..., 3)``."""
        xyz = np.asarray(xyz, dtype=float)
        inv = np.linalg.inv(self.affine)
        return xyz @ inv[:3, :3].T + inv[:3, 3]

    def corners(self) -> np.ndarray:
        """(8, 3) world RAS+ mm of the eight corner voxel centres."""
        nz, ny, nx = self.shape
        ijk = np.array([[i, j, k] for k in (0, nz - 1) for j in (0, ny - 1) for i in (0, nx - 1)], float)
        return self.index_to_world(ijk)

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """World axis-aligned bounding box ``(lo, hi)``, each (3,) RAS+ mm, of the voxel centres."""
        c = self.corners()
        return c.min(axis=0), c.max(axis=0)

    @property
    def center(self) -> np.ndarray:
        """World RAS+ mm of the volume's centre (middle of the voxel-centre box)."""
        nz, ny, nx = self.shape
        return self.index_to_world([(nx - 1) / 2, (ny - 1) / 2, (nz - 1) / 2])

    @property
    def extent(self) -> np.ndarray:
        """Physical size ``(x, y, z)`` in mm of the voxel-centre box along voxel axes i, j, k."""
        nz, ny, nx = self.shape
        return np.array([(nx - 1) * self.spacing[2], (ny - 1) * self.spacing[1], (nz - 1) * self.spacing[0]])

    @property
    def thin_axis(self) -> int | None:
        """The array axis (0 = z, 1 = y, 2 = x) along which the volume is a slab (a single slice, a few frames):
        less than :data:`SLAB` as thick, samples times spacing, as along the next thinnest; None for a volume that
        is no slab."""
        thick = np.asarray(self.shape[:3], dtype=float) * np.asarray(self.spacing)
        order = np.argsort(thick, kind="stable")
        return int(order[0]) if thick[order[0]] < SLAB * thick[order[1]] else None

    @property
    def diagonal(self) -> float:
        """Length in mm of the voxel-centre box's diagonal."""
        return float(np.linalg.norm(self.extent))

    # -- values ---------------------------------------------------------------
    def luminance(self) -> np.ndarray:
        """float32 ``(nz, ny, nx)``: Rec. 601 luma ``0.299 R + 0.587 G + 0.114 B`` of a colour
        volume (in the data's units), or the scalar data itself as float32."""
        if not self.is_color:
            return self.data.astype(np.float32, copy=False)
        w = np.asarray(LUMA_WEIGHTS, np.float32)
        return np.ascontiguousarray(self.data.astype(np.float32, copy=False) @ w)

    def value_range(self) -> tuple[float, float]:
        """``(min, max)`` over finite values (NaN and inf ignored); of chunked data with stored per-chunk ranges
        (an OME-Zarr written by volumen), from those, without reading the data."""
        d = self.data
        ranges = getattr(d, "chunk_ranges", None) if is_chunked(d) else None
        if ranges is not None:
            lows, highs = (np.asarray(r, float) for r in ranges)
            lows, highs = lows[np.isfinite(lows)], highs[np.isfinite(highs)]
            if lows.size == np.asarray(ranges[0]).size and highs.size == lows.size:
                return float(lows.min()), float(highs.max())
        if np.issubdtype(d.dtype, np.floating) and not np.all(np.isfinite(d)):
            finite = d[np.isfinite(d)]
            if finite.size == 0:
                return (float("nan"), float("nan"))
            return float(finite.min()), float(finite.max())
        return float(d.min()), float(d.max())

    def histogram(self, bins: int = 256, range: tuple[float, float] | None = None):
        """Histogram of finite values: ``(counts (bins,), edges (bins + 1,))`` in the data's units."""
        lo, hi = self.value_range() if range is None else range
        if not hi > lo:
            hi = lo + 1.0
        d = self.data
        if np.issubdtype(d.dtype, np.floating):
            d = d[np.isfinite(d)]
        return np.histogram(d, bins=bins, range=(lo, hi))

    # -- derived volumes ------------------------------------------------------
    def with_data(self, data: np.ndarray, **changes) -> Volume:
        """A volume on the same grid with other values (a mask, a filtered copy; scalar or colour)."""
        kw = dict(spacing=self.spacing, affine=self.affine.copy(), modality=self.modality,
                  units=self.units, name=self.name, meta=dict(self.meta))
        kw.update(changes)
        if np.asarray(data).shape[:3] != self.shape:
            raise ValueError(f"new data grid {np.asarray(data).shape[:3]} differs from {self.shape}")
        return Volume(data, **kw)

    def slab(self) -> Volume:
        """The volume as it is drawn in 3-D: itself, or where an axis holds one sample (a single slice) that sample
        twice, half its spacing (the slice thickness) either side of it. A volume is drawn between its voxel
        centres, so one sample alone spans nothing (a ray through it composites nothing); the slab is as thick as
        the slice. Its data is a copy; a volume with no single-sample axis is returned as it is."""
        data, affine = slab_grid(self.data, self.affine)
        if data is self.data:
            return self
        return Volume(data, affine=affine, modality=self.modality, units=self.units, name=self.name,
                      meta=dict(self.meta))

    def crop(self, z: slice | tuple = slice(None), y: slice | tuple = slice(None),
             x: slice | tuple = slice(None)) -> Volume:
        """Sub-volume by index ranges ``[z, y, x]`` (slices or ``(start, stop)``); the affine is shifted
        so every kept voxel keeps its world position. The data is a copy."""
        sl = [s if isinstance(s, slice) else slice(*s) for s in (z, y, x)]
        for s in sl:
            if s.step not in (None, 1):
                raise ValueError("crop takes contiguous ranges (step 1)")
        starts = [s.indices(n)[0] for s, n in zip(sl, self.shape, strict=True)]
        data = self.data[tuple(sl)]
        if min(data.shape) < 1:
            raise ValueError(f"crop {z, y, x} leaves an empty volume")
        aff = self.affine.copy()
        aff[:3, 3] = self.index_to_world([starts[2], starts[1], starts[0]])
        return Volume(np.array(data), spacing=self.spacing, affine=aff, modality=self.modality,
                      units=self.units, name=self.name, meta=dict(self.meta))

    def resample(self, spacing: float | tuple[float, float, float] | None = None, order: int = 1,
                 mode: str = "nearest") -> Volume:
        """Resample onto a grid of ``spacing`` mm (a number for isotropic, or ``(dz, dy, dx)``).

        Default: isotropic at the smallest current spacing. The new grid starts at
        voxel (0, 0, 0) of the old one and covers the same voxel-centre box;
        interpolation is ``scipy.ndimage.zoom``-style spline of ``order``
        (1 = trilinear), each colour channel on its own. Integer data is rounded
        back to its dtype.
        """
        from scipy import ndimage

        if spacing is None:
            spacing = min(self.spacing)
        new = np.broadcast_to(np.asarray(spacing, dtype=float), (3,)).astype(float)
        if np.any(new <= 0):
            raise ValueError("spacing must be positive")
        old = np.array(self.spacing)
        n_old = np.array(self.shape)
        n_new = np.maximum(np.floor((n_old - 1) * old / new + 1e-6).astype(int) + 1, 1)
        # output index o maps to input index o * new / old (same first voxel centre)
        scale = new / old
        src = self.data
        work = src.astype(np.float32) if src.dtype.kind in "iub" else src
        if self.is_color:
            out = np.stack([ndimage.affine_transform(work[..., c], scale, output_shape=tuple(n_new), order=order,
                                                     mode=mode) for c in range(3)], axis=-1)
        else:
            out = ndimage.affine_transform(work, scale, output_shape=tuple(n_new), order=order, mode=mode)
        if src.dtype.kind in "iu":
            info = np.iinfo(src.dtype)
            out = np.clip(np.rint(out), info.min, info.max).astype(src.dtype)
        elif src.dtype.kind == "b":
            out = out > 0.5
        aff = self.affine.copy()
        aff[:3, :3] = self.direction * new[::-1]
        meta = dict(self.meta)
        meta["resampled_from"] = {"spacing": list(self.spacing), "shape": list(self.shape)}
        return Volume(out, spacing=tuple(new), affine=aff, modality=self.modality, units=self.units,
                      name=self.name, meta=meta)

    def _repr_png_(self) -> bytes:
        """Notebook display: the axial, coronal and sagittal planes through the centre (:mod:`._repr`)."""
        return picture("volume_png", self)

    def _repr_html_(self) -> str:
        """Notebook display: the geometry as a table beside the three planes (:mod:`._repr`)."""
        return picture("volume_html", self)

    def __repr__(self) -> str:
        lo, hi = self.value_range()
        grid = f"shape(z,y,x,rgb)={self.data.shape}" if self.is_color else f"shape(z,y,x)={self.shape}"
        return (f"Volume(name={self.name!r}, {grid}, spacing(dz,dy,dx)="
                f"{tuple(round(s, 4) for s in self.spacing)} mm, orientation={self.orientation}, "
                f"modality={self.modality}, range=[{lo:g}, {hi:g}] {self.units})")
