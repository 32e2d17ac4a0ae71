"""Bricks: a volume cut into boxes of cells, each drawn as its own small Volume and equal, where it is drawn,
to the whole.

A brick owns the cells between voxel centres ``lo .. hi`` (inclusive, global
``[z, y, x]`` indices; neighbours share the boundary voxel, the one-voxel
overlap trilinear interpolation needs) and reads ``pad`` more voxels each side
when the shading needs gradients there. It is drawn clipped to its own cell
box, and its rays follow the whole volume's sample grid
(``volumen.render.raycast.render_part``), so every sample of the whole ray
falls in exactly one brick: the box is a world crop when the affine is
axis-aligned (neighbours then compute the same ray parameter at their shared
face, bit for bit), else a voxel crop. Its values are normalized with the
whole volume's range (:class:`BrickVolume`), so each brick samples the same
table entries the whole volume would.

Visibility order: bricks sorted by the distance from the eye (orthographic:
the depth along the view) to the centre of their cell of a uniform grid. Two
cells sharing a face are then in the order a ray crossing that face meets them
(the eye lies on the nearer centre's side), and so, link by link, are all the
bricks one ray meets.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, replace

import numpy as np

from ...core import Clipping, Volume

__all__ = ["Brick", "BrickVolume", "brick_grid", "visibility_order", "brick_scene", "needs_gradients",
           "screen_tiles"]


@dataclass(frozen=True)
class Brick:
    """Cells ``lo .. hi`` (voxel centres, inclusive, [z, y, x]) and the voxels read ``rlo .. rhi`` (exclusive)."""

    index: tuple[int, int, int]
    lo: tuple[int, int, int]
    hi: tuple[int, int, int]
    rlo: tuple[int, int, int]
    rhi: tuple[int, int, int]

    @property
    def read_slices(self) -> tuple[slice, slice, slice]:
        return tuple(slice(a, b) for a, b in zip(self.rlo, self.rhi, strict=True))

    @property
    def nbytes_per_item(self) -> int:
        return int(np.prod(np.subtract(self.rhi, self.rlo)))


class BrickVolume(Volume):
    """A brick's Volume: its value range is the whole volume's table range (so its table is the whole volume's)."""

    whole_range: tuple[float, float] = (0.0, 1.0)
    #: whether the brick holds values past ``whole_range`` (a fill cut off the table: ``core.table_range``), which
    #: its samples clamp (a copy, never its data in place)
    clamps: bool = False
    #: the brick's own least and greatest value when the source stores no per-chunk ranges (else None)
    block_range: tuple[float, float] | None = None

    def value_range(self) -> tuple[float, float]:
        return self.whole_range


def _edges(n: int, size: int) -> list[int]:
    if n <= 1:
        return [0, 0]
    return list(range(0, n - 1, size)) + [n - 1]


def brick_grid(shape, size: int, pad: int = 0) -> list[Brick]:
    """The bricks of a ``shape`` [z, y, x] volume with cells ``size`` voxels on a side."""
    edges = [_edges(n, int(size)) for n in shape]
    bricks = []
    for idx in itertools.product(*(range(len(e) - 1) for e in edges)):
        lo = tuple(e[i] for e, i in zip(edges, idx, strict=True))
        hi = tuple(e[i + 1] for e, i in zip(edges, idx, strict=True))
        rlo = tuple(max(a - pad, 0) for a in lo)
        rhi = tuple(min(b + pad, n - 1) + 1 for b, n in zip(hi, shape, strict=True))
        bricks.append(Brick(idx, lo, hi, rlo, rhi))
    return bricks


def visibility_order(bricks, affine, size: int, camera) -> list[Brick]:
    """``bricks`` front to back for ``camera`` (see the module docstring)."""
    eye = np.asarray(camera.position, float)
    fwd = camera.basis()[2]
    ortho = camera.projection == "orthographic"

    def key(b):
        c = np.array(b.lo, float)[::-1] + size / 2.0  # centre of its uniform-grid cell, (i, j, k)
        w = affine[:3, :3] @ c + affine[:3, 3]
        return float(np.dot(w - eye, fwd)) if ortho else float(np.linalg.norm(w - eye))

    return sorted(bricks, key=key)


def _axis_aligned(affine) -> bool:
    m = np.abs(np.asarray(affine)[:3, :3]) > 0
    return bool(np.all(m.sum(axis=0) == 1) and np.all(m.sum(axis=1) == 1))


def _cell_box(brick, clipping):
    """The brick's cells as (lo, hi) in global (i, j, k) indices, intersected with a voxel crop."""
    lo, hi = np.array(brick.lo[::-1], float), np.array(brick.hi[::-1], float)
    if clipping.crop is not None and clipping.crop_space == "voxel":
        c = np.asarray(clipping.crop, float)
        lo, hi = np.maximum(lo, c[0::2]), np.minimum(hi, c[1::2])
    return lo, hi


def brick_clipping(brick, affine, clipping) -> Clipping | None:
    """The brick's :class:`Clipping` (its cell box, the scene's crop and planes), None when nothing is left."""
    lo, hi = _cell_box(brick, clipping)
    if np.any(hi < lo):
        return None
    if _axis_aligned(affine):
        corners = np.array(list(itertools.product(*zip(lo, hi, strict=True))))
        w = corners @ np.asarray(affine)[:3, :3].T + np.asarray(affine)[:3, 3]
        wlo, whi = w.min(axis=0), w.max(axis=0)
        if clipping.crop is not None and clipping.crop_space == "world":
            c = np.asarray(clipping.crop, float)
            wlo, whi = np.maximum(wlo, c[0::2]), np.minimum(whi, c[1::2])
            if np.any(whi < wlo):
                return None
        crop = tuple(float(v) for pair in zip(wlo, whi, strict=True) for v in pair)
        return Clipping(crop=crop, crop_space="world", planes=clipping.planes)
    off = np.array(brick.rlo[::-1], float)
    crop = tuple(float(v) for pair in zip(lo - off, hi - off, strict=True) for v in pair)
    return Clipping(crop=crop, crop_space="voxel", planes=clipping.planes)  # oblique: a voxel crop


def brick_volume(brick, data: np.ndarray, whole, value_range, clamps: bool = False) -> BrickVolume:
    """The brick's Volume: ``data`` read at ``brick.read_slices`` of ``whole`` (a Volume or a pyramid Level);
    ``value_range`` the whole volume's table range, ``clamps`` whether ``data`` reaches past it."""
    m = np.eye(4)
    m[:3, 3] = brick.rlo[::-1]
    v = BrickVolume(data, spacing=whole.spacing, affine=np.asarray(whole.affine) @ m)
    v.whole_range = (float(value_range[0]), float(value_range[1]))
    v.clamps = bool(clamps)
    return v


def needs_gradients(scene) -> bool:
    """Whether the scene's drawing reads gradients (normals): bricks then read one more voxel each side."""
    lit = scene.shading.mode != "none" and scene.mode in ("composite", "isosurface")
    return lit or scene.transfer.gradient_opacity is not None


def brick_scene(scene, volume, clipping):
    """The scene drawn for one brick: its volume and clipping."""
    return replace(scene, volume=volume, clipping=clipping)


def screen_tiles(brick, affine, camera, size, tile: int) -> np.ndarray | None:
    """Indices (row-major) of the ``tile``-pixel tiles of a ``size = (w, h)`` picture that the brick's cells
    may cover (their projected bounding box, one pixel wider); None (every tile) when a corner lies behind a
    perspective eye."""
    corners = np.array(list(itertools.product(*zip(brick.lo[::-1], brick.hi[::-1], strict=True))), float)
    w = corners @ np.asarray(affine)[:3, :3].T + np.asarray(affine)[:3, 3]
    if camera.projection == "perspective" and np.any((w - camera.position) @ camera.basis()[2] <= 1e-6):
        return None
    colrow, _ = camera.project(w, size)
    ntx, nty = -(-int(size[0]) // tile), -(-int(size[1]) // tile)
    x0, y0 = (np.floor(colrow.min(axis=0)) - 1) // tile
    x1, y1 = (np.floor(colrow.max(axis=0)) + 1) // tile
    xs = np.arange(max(int(x0), 0), min(int(x1), ntx - 1) + 1)
    ys = np.arange(max(int(y0), 0), min(int(y1), nty - 1) + 1)
    return (ys[:, None] * ntx + xs[None, :]).ravel().astype(np.int64)


def brick_visible(scene, bmin: float, bmax: float, value_range) -> bool:
    """Whether a brick with values in ``[bmin, bmax]`` can show anything (composite: some opacity there; widened
    by a thousandth of the whole range, more than the table's half step, since samples read the nearest entry)."""
    if scene.mode != "composite":
        return True
    lo, hi = scene.transfer.visible_range()
    eps = (value_range[1] - value_range[0]) / 1000.0
    return bool(bmax + eps >= lo and bmin - eps <= hi)
