"""OME-Zarr (and plain Zarr) volumes: Zarr v2 / v3 local directories, read lazily, written as a pyramid.

Reading: a multiscale image group (OME-NGFF 0.4 on Zarr v2: ``multiscales``
in the group's attributes; 0.5 on Zarr v3: under ``ome``) or a bare 3-D
array. ``level`` picks the pyramid level (0 = full resolution). The Volume's
``data`` is a :class:`~volumen.io._chunked.ChunkedArray`: nothing is read
until values are asked for, and then only the chunks they lie in.

Geometry (RAS <-> OME). OME axes are ``(z, y, x)`` with a per-level ``scale``
and ``translation`` in physical units (here millimetre); volumen reads them as
``affine = [[dx, 0, 0, tx], [0, dy, 0, ty], [0, 0, dz, tz]]``, i.e. OME's
``x, y, z`` are taken as RAS+ ``R, A, S``. Volumes written by volumen also
keep their exact affine (oblique, flipped, LPS-derived) under the group
attribute ``volumen.affine`` (level 0), which wins over scale/translation
when present; OME's scale is then the spacing and translation the affine's
origin, so other viewers show the right size and place.

Pyramid: level ``L + 1`` is the 2x2x2 mean of level ``L`` (odd edges repeat
their last voxel), so its voxel ``c`` is centred on fine index ``2c + 0.5``:
``scale`` doubles and ``translation`` moves by half a fine voxel. The writer
streams slabs of one chunk depth, so memory stays at a few slabs; it also
stores every level's per-chunk minima and maxima (``volumen.ranges``), which
the out-of-core renderer uses for empty-space skipping.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..core import Volume, display_range, hu_offset
from ..errors import CorruptDataError, VolumeReadError, VolumeWriteError
from ._chunked import ChunkedArray

__all__ = ["read", "write", "is_zarr", "open_levels", "Level"]


def is_zarr(path) -> bool:
    p = Path(path)
    return p.is_dir() and any((p / m).exists() for m in ("zarr.json", ".zgroup", ".zarray"))


def _multiscale(attrs: dict) -> dict | None:
    ome = attrs.get("ome", attrs)
    ms = ome.get("multiscales")
    return ms[0] if ms else None


def _level_affine(base: np.ndarray, factor: np.ndarray) -> np.ndarray:
    """Affine of a level whose voxel ``c`` is centred on level-0 index ``factor * c + (factor - 1) / 2`` (xyz)."""
    m = np.eye(4)
    m[:3, :3] = np.diag(factor)
    m[:3, 3] = (factor - 1) / 2
    return base @ m


def _ome_affine(ds: dict) -> np.ndarray:
    scale, trans = np.ones(3), np.zeros(3)
    for t in ds.get("coordinateTransformations", []):
        if t.get("type") == "scale":
            scale = np.asarray(t["scale"][-3:], float)
        elif t.get("type") == "translation":
            trans = np.asarray(t["translation"][-3:], float)
    aff = np.eye(4)
    aff[:3, :3] = np.diag(scale[::-1])
    aff[:3, 3] = trans[::-1]
    return aff


class Level:
    """One pyramid level: its lazy array, affine, and per-chunk value ranges (None when not stored)."""

    def __init__(self, array: ChunkedArray, affine: np.ndarray, cmin=None, cmax=None):
        self.array, self.affine, self.cmin, self.cmax = array, affine, cmin, cmax

    @property
    def shape(self):
        return self.array.shape

    @property
    def spacing(self) -> tuple[float, float, float]:
        return tuple(float(np.linalg.norm(self.affine[:3, a])) for a in (2, 1, 0))


def open_levels(path) -> tuple[list[Level], dict]:
    """Every level of the image at ``path`` (finest first) and the group's ``volumen`` attributes."""
    import zarr

    p = Path(path)
    if not p.exists():
        raise VolumeReadError(p, "does not exist")
    try:
        node = zarr.open(str(p), mode="r")
    except (ValueError, KeyError, FileNotFoundError) as exc:
        raise CorruptDataError(p, f"is not a readable Zarr store ({exc})") from exc
    if isinstance(node, zarr.Array):
        if node.ndim != 3:
            raise CorruptDataError(p, f"holds a {node.ndim}-d array; volumen reads 3-d [z, y, x] arrays")
        return [Level(ChunkedArray(node), np.eye(4))], {}
    attrs = dict(node.attrs)
    ms = _multiscale(attrs)
    if ms is None:
        raise CorruptDataError(p, "is a Zarr group without OME multiscales metadata")
    extra = attrs.get("volumen", {})
    base = np.asarray(extra["affine"], float) if "affine" in extra else None
    ranges = extra.get("ranges", [])
    levels = []
    for n, ds in enumerate(ms["datasets"]):
        arr = node[ds["path"]]
        if arr.ndim < 3 or any(s != 1 for s in arr.shape[:-3]):
            raise CorruptDataError(p, f"level {ds['path']} has shape {arr.shape}; volumen reads 3-d images")
        if arr.ndim > 3:
            arr = _Squeezed(arr)
        aff = _ome_affine(ds)
        if base is not None:
            f0 = np.linalg.norm(_ome_affine(ms["datasets"][0])[:3, :3], axis=0)
            aff = _level_affine(base, np.linalg.norm(aff[:3, :3], axis=0) / f0)
        r = ranges[n] if n < len(ranges) else None
        cr = (np.asarray(r["min"]), np.asarray(r["max"])) if r else None
        levels.append(Level(ChunkedArray(arr, ranges=cr), aff, *(cr or ())))
    return levels, extra


class _Squeezed:
    """A (1, .., 1, z, y, x) array seen as (z, y, x)."""

    def __init__(self, arr):
        self.arr, self.lead = arr, (0,) * (arr.ndim - 3)
        self.shape, self.dtype, self.chunks = arr.shape[-3:], arr.dtype, arr.chunks[-3:]

    def __getitem__(self, key):
        return self.arr[self.lead + tuple(key)]


def read(path, *, level: int = 0) -> Volume:
    """The Volume of pyramid level ``level`` at ``path``, its data a lazy :class:`ChunkedArray`."""
    levels, extra = open_levels(path)
    if not 0 <= level < len(levels):
        raise VolumeReadError(Path(path), f"has pyramid levels 0..{len(levels) - 1}, not {level}")
    lv = levels[level]
    meta = {"source": str(path), "format": "zarr", "level": level, "levels": len(levels), "warnings": []}
    return Volume(lv.array, spacing=lv.spacing, affine=lv.affine, modality=extra.get("modality", "OT"),
                  units=extra.get("units", ""), name=extra.get("name", Path(path).name), meta=meta)


def _halve(a: np.ndarray, floor: float | None = None) -> np.ndarray:
    """2x2x2 mean (odd edges repeat the last voxel), in the input's dtype (integers rounded). Summed in float64:
    in float32 eight values near its lowest (a resampler's fill) overflowed to -inf. ``floor``: values below it (a
    fill outside the field of view, ``core.display_range``) are left out of the means, a block of nothing else
    keeps the fill: averaged into the tissue at the field of view's edge, they made a band of values between,
    which the coarser levels' display ranges then started in."""
    pad = [(0, n % 2) for n in a.shape]
    if any(p[1] for p in pad):
        a = np.pad(a, pad, mode="edge")
    z, y, x = a.shape
    blocks = a.reshape(z // 2, 2, y // 2, 2, x // 2, 2)
    if floor is None:
        m = blocks.mean(axis=(1, 3, 5), dtype=np.float64)
    else:
        kept = blocks >= floor
        n = kept.sum(axis=(1, 3, 5))
        total = np.where(kept, blocks, 0).sum(axis=(1, 3, 5), dtype=np.float64)
        m = np.where(n > 0, total / np.maximum(n, 1), blocks.min(axis=(1, 3, 5)))
    return np.rint(m).astype(a.dtype) if a.dtype.kind in "iu" else m.astype(a.dtype)


def _fill_floor(volume) -> float | None:
    """The bottom of ``volume``'s display range where it cuts a fill off (``core.display_range``), else None. Not
    asked of a CT (its display range is its data range): a pass over the data less, which a lazy source (``make
    huge``'s 8 GiB) would compute again."""
    if hu_offset(volume) is not None:
        return None
    lo, hi = volume.value_range()
    bottom = display_range(volume, (lo, hi))[0]
    return bottom if bottom > lo else None


def _chunk_ranges(slab: np.ndarray, c: int):
    """Per-chunk (min, max) of a slab one chunk deep: arrays (ny_chunks, nx_chunks)."""
    _, y, x = slab.shape
    ny, nx = -(-y // c), -(-x // c)
    lo, hi = np.empty((ny, nx)), np.empty((ny, nx))
    for j in range(ny):
        for i in range(nx):
            b = slab[:, j * c:(j + 1) * c, i * c:(i + 1) * c]
            lo[j, i], hi[j, i] = b.min(), b.max()
    return lo, hi


def _shapes(shape, chunk, levels):
    out = [tuple(shape)]
    while (levels is None and max(out[-1]) > chunk) or (levels is not None and len(out) < levels):
        if min(out[-1]) < 2:
            break
        out.append(tuple(-(-n // 2) for n in out[-1]))
    return out


def write(volume: Volume, path, *, chunks: int = 64, levels: int | None = None, zarr_format: int = 3) -> None:
    """Write ``volume`` as an OME-Zarr pyramid (0.5 on Zarr v3, or 0.4 with ``zarr_format=2``).

    ``levels``: how many (default: halve until the coarsest fits one chunk). The
    data is streamed slab by slab (``volume.data`` may itself be chunked).
    """
    import zarr

    p = Path(path)
    if volume.is_color:
        raise VolumeWriteError(p, "is to hold a colour volume; OME-Zarr writing takes scalar volumes")
    if zarr_format not in (2, 3):
        raise VolumeWriteError(p, f"zarr_format must be 2 or 3, got {zarr_format}")
    c = int(chunks)
    shapes = _shapes(volume.shape, c, levels)
    floor = _fill_floor(volume)
    root = zarr.open_group(str(p), mode="w", zarr_format=zarr_format)
    arrays = [root.create_array(str(n), shape=s, chunks=(c, c, c), dtype=volume.dtype) for n, s in enumerate(shapes)]
    ranges = []
    for n, arr in enumerate(arrays):
        src = volume.data if n == 0 else arrays[n - 1]
        lo, hi = [], []
        for z in range(0, arr.shape[0], c):
            slab = np.asarray(src[z:z + c] if n == 0 else src[2 * z:2 * (z + c)])
            slab = slab if n == 0 else _halve(slab, floor)
            arr[z:z + slab.shape[0]] = slab
            a, b = _chunk_ranges(slab, c)
            lo.append(a)
            hi.append(b)
        ranges.append({"min": np.stack(lo).tolist(), "max": np.stack(hi).tolist()})
    dz, dy, dx = volume.spacing
    datasets = []
    for n in range(len(shapes)):
        f = 2.0 ** n
        org = volume.affine[:3, 3][::-1] + (f - 1) / 2 * np.array([dz, dy, dx])
        datasets.append({"path": str(n), "coordinateTransformations": [
            {"type": "scale", "scale": [dz * f, dy * f, dx * f]},
            {"type": "translation", "translation": [float(v) for v in org]}]})
    axes = [{"name": a, "type": "space", "unit": "millimeter"} for a in "zyx"]
    ms = {"axes": axes, "datasets": datasets, "name": volume.name or p.stem}
    ome = {"multiscales": [{"version": "0.4", **ms}]} if zarr_format == 2 else \
        {"ome": {"version": "0.5", "multiscales": [ms]}}
    extra = {"affine": np.asarray(volume.affine, float).tolist(), "modality": volume.modality, "units": volume.units,
             "name": volume.name, "chunk": c, "ranges": ranges}
    root.attrs.update({**ome, "volumen": extra})
