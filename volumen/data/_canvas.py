"""The drawing surface of the phantoms: an axis-aligned RAS grid and a float HU canvas.

A phantom is painted back to front: each primitive computes an (approximate)
signed distance ``sd`` in millimetres (< 0 inside) on the voxels of its bounding
box only, and the builder blends a value in by the voxel's *coverage*
``clip(0.5 - sd / h, 0, 1)`` (``h`` the voxel size): the partial-volume edge of a
real CT, without which every surface is a voxel staircase that renders as
terraces (:meth:`Canvas.paint`). The coverage passes 0.5 exactly where the voxel's
centre crosses the surface, so "centre inside" (``sd < 0``, the ground-truth
masks) is "value on the far side of the half-way threshold". Shapes combine as
signed distances: intersection ``max(a, b)``, union ``min(a, b)``, complement
``-a``; layers (skin over fat over muscle) and shells (a skull of varying
thickness) are offsets of one distance, and every primitive stays vectorised.

World coordinates follow docs/design.md section 2: RAS+ millimetres; voxel ``(i, j, k)``
(column, row, slice) sits at ``origin + (i * dx, j * dy, k * dz)``, so the
affine is diagonal with i toward the patient's Right, j Anterior, k Superior.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from ..core import Volume

__all__ = ["VoxelGrid", "Region", "Canvas", "ellipsoid_sd", "ellipsoid_support", "sphere_sd", "ellipse_cylinder_sd",
           "box_sd", "coverage", "smooth_union", "surface_point"]


@dataclass(frozen=True)
class Region:
    """The voxels of a bounding box: index slices ``[z, y, x]`` and open world coordinate grids (mm)."""

    slices: tuple[slice, slice, slice]
    z: np.ndarray  # (nz, 1, 1) float32, world z of each slice
    y: np.ndarray  # (1, ny, 1)
    x: np.ndarray  # (1, 1, nx)


@dataclass(frozen=True)
class VoxelGrid:
    """An axis-aligned RAS grid: ``shape`` (nz, ny, nx), ``spacing`` (dz, dy, dx) mm, ``origin`` xyz mm of voxel 0."""

    shape: tuple[int, int, int]
    spacing: tuple[float, float, float]
    origin: tuple[float, float, float]

    @classmethod
    def centred(cls, fov_xyz, size, center=(0.0, 0.0, 0.0)) -> VoxelGrid:
        """A grid covering ``fov_xyz`` (x, y, z) mm around ``center``.

        ``size`` is the voxel count along the longest axis (isotropic voxels) or a
        tuple ``(nz, ny, nx)`` (each axis spans its field of view).
        """
        fov = np.asarray(fov_xyz, dtype=float)
        if np.ndim(size) == 0:
            n_long = _check_count(size)
            h = fov.max() / n_long
            n_xyz = np.maximum(np.rint(fov / h).astype(int), 1)
            h_xyz = np.full(3, h)
        else:
            counts = tuple(size)
            if len(counts) != 3:
                raise ValueError(f"size must be an int or a tuple (nz, ny, nx), got {size!r}")
            n_xyz = np.array([_check_count(n) for n in counts[::-1]])
            h_xyz = fov / n_xyz
        origin = np.asarray(center, float) - (n_xyz - 1) / 2.0 * h_xyz
        return cls(tuple(int(n) for n in n_xyz[::-1]), tuple(float(h) for h in h_xyz[::-1]),
                   tuple(float(o) for o in origin))

    @property
    def affine(self) -> np.ndarray:
        """(4, 4) voxel (i, j, k, 1) -> world RAS+ mm."""
        aff = np.diag([self.spacing[2], self.spacing[1], self.spacing[0], 1.0])
        aff[:3, 3] = self.origin
        return aff

    def axis(self, a: int) -> np.ndarray:
        """World coordinates (mm, float64) of the voxel centres along world axis ``a`` (0=x, 1=y, 2=z)."""
        n = self.shape[2 - a]
        return self.origin[a] + np.arange(n) * self.spacing[2 - a]

    def index(self, xyz) -> np.ndarray:
        """World (..., 3) xyz mm -> nearest voxel indices (..., 3) as (k, j, i) = (slice, row, column), unclipped."""
        xyz = np.asarray(xyz, dtype=float)
        ijk = (xyz - np.asarray(self.origin)) / np.asarray(self.spacing[::-1])
        return np.rint(ijk[..., ::-1]).astype(int)

    def region(self, lo_xyz=None, hi_xyz=None) -> Region | None:
        """Voxels whose centres lie in the world box ``[lo, hi]`` (whole grid when omitted); None when empty."""
        sl = []
        for a in range(3):
            n = self.shape[2 - a]
            h = self.spacing[2 - a]
            lo = 0 if lo_xyz is None else int(np.ceil((lo_xyz[a] - self.origin[a]) / h - 1e-9))
            hi = n - 1 if hi_xyz is None else int(np.floor((hi_xyz[a] - self.origin[a]) / h + 1e-9))
            lo, hi = max(lo, 0), min(hi, n - 1)
            if hi < lo:
                return None
            sl.append(slice(lo, hi + 1))
        sx, sy, sz = sl
        x = self.axis(0)[sx].astype(np.float32)[None, None, :]
        y = self.axis(1)[sy].astype(np.float32)[None, :, None]
        z = self.axis(2)[sz].astype(np.float32)[:, None, None]
        return Region((sz, sy, sx), z, y, x)

    def around(self, center, half_extent) -> Region | None:
        """Region of the box ``center +- half_extent`` (mm, scalar or xyz)."""
        c = np.asarray(center, float)
        e = np.broadcast_to(np.asarray(half_extent, float), (3,))
        return self.region(c - e, c + e)


def _check_count(n) -> int:
    if int(n) != n or int(n) < 2:
        raise ValueError(f"voxel counts must be integers >= 2, got {n!r}")
    return int(n)


def ellipsoid_sd(reg: Region, center, semi_axes, rotation=None) -> np.ndarray:
    """Approximate signed distance (mm, <0 inside) to an ellipsoid, ``F / |grad F|``.

    ``semi_axes`` (mm) lie along world x, y, z, or along the columns of the 3x3
    ``rotation`` (unit vectors in world xyz) when given. Exact on the surface and
    for a sphere; within a few per cent of the true distance near the surface of
    a moderately eccentric ellipsoid.
    """
    px, py, pz = (c - np.float32(o) for c, o in zip((reg.x, reg.y, reg.z), center, strict=True))
    if rotation is not None:
        r = np.asarray(rotation, dtype=np.float32)
        px, py, pz = (px * r[0, a] + py * r[1, a] + pz * r[2, a] for a in range(3))
    a, b, c = (float(s) for s in semi_axes)
    ux, uy, uz = px / a, py / b, pz / c
    f = ux * ux + uy * uy + uz * uz
    grad = np.sqrt((ux / a) ** 2 + (uy / b) ** 2 + (uz / c) ** 2)
    with np.errstate(divide="ignore", invalid="ignore"):
        sd = (f - 1.0) / (2.0 * grad)
    sd = np.where(grad > 0, sd, -min(a, b, c))
    return sd.astype(np.float32, copy=False)


def ellipsoid_support(center, semi_axes, rotation, direction) -> np.ndarray:
    """The point (xyz mm) of an ellipsoid (as in :func:`ellipsoid_sd`) furthest along ``direction``."""
    r = np.eye(3) if rotation is None else np.asarray(rotation, float)
    m = r @ np.diag(np.asarray(semi_axes, float) ** 2) @ r.T
    d = np.asarray(direction, float)
    return np.asarray(center, float) + m @ d / np.sqrt(d @ m @ d)


def sphere_sd(reg: Region, center, radius: float) -> np.ndarray:
    """Exact signed distance (mm, <0 inside) to a sphere."""
    cx, cy, cz = (float(c) for c in center)
    return (np.sqrt((reg.x - cx) ** 2 + (reg.y - cy) ** 2 + (reg.z - cz) ** 2) - float(radius)).astype(np.float32)


def smooth_union(a: np.ndarray, b: np.ndarray, k: float) -> np.ndarray:
    """Union of two signed distances (mm) with creases rounded over ``k`` mm (polynomial smooth minimum)."""
    h = np.maximum(k - np.abs(a - b), 0.0) / k
    return np.minimum(a, b) - h * h * (k / 4.0)


def ellipse_cylinder_sd(reg: Region, center_xy, semi_xy, z_range) -> np.ndarray:
    """Approximate signed distance (mm) to an elliptic cylinder along z, capped at ``z_range`` (lo, hi)."""
    cx, cy = (float(c) for c in center_xy)
    a, b = (float(s) for s in semi_xy)
    ux, uy = (reg.x - cx) / a, (reg.y - cy) / b
    f = ux * ux + uy * uy
    grad = np.sqrt((ux / a) ** 2 + (uy / b) ** 2)
    with np.errstate(divide="ignore", invalid="ignore"):
        side = np.where(grad > 0, (f - 1.0) / (2.0 * grad), -min(a, b))
    lo, hi = z_range
    cap = np.maximum(lo - reg.z, reg.z - hi)
    return np.maximum(side, cap).astype(np.float32)


def box_sd(reg: Region, lo_xyz, hi_xyz) -> np.ndarray:
    """Signed distance (mm) to an axis-aligned box ``[lo, hi]`` (exact outside near the faces, and inside)."""
    d = [np.abs(c - np.float32((lo + hi) / 2.0)) - np.float32((hi - lo) / 2.0)
         for c, lo, hi in zip((reg.x, reg.y, reg.z), lo_xyz, hi_xyz, strict=True)]
    inside = np.minimum(np.maximum(np.maximum(d[0], d[1]), d[2]), 0.0)
    outside = np.sqrt(sum(np.maximum(di, 0.0) ** 2 for di in d))
    return (inside + outside).astype(np.float32)


def coverage(sd, h: float, sigma: float = 0.0) -> np.ndarray:
    """Partial-volume coverage (float32 in [0, 1]) of a voxel of size ``h`` mm at signed distance ``sd`` (mm)
    from a surface, seen by a scanner of point-spread ``sigma`` mm (Gaussian).

    Without blur it is the voxel's box across the surface, a linear ramp ``clip(0.5 - sd / h, 0, 1)``;
    with it, that ramp convolved with the Gaussian, ``(sigma / h) (G((h/2 - sd) / sigma) - G((-h/2 - sd) /
    sigma))`` where ``G(x) = x Phi(x) + phi(x)``: a smooth profile, evaluated at the voxel centres
    (so it is sampled without aliasing, unlike a blur of the sampled ramp). Either is 1 inside, 0
    outside and exactly 0.5 where the voxel's centre is on the surface.
    """
    sd = np.asarray(sd, np.float32)
    if sigma <= 0:
        return np.clip(np.float32(0.5) - sd * np.float32(1.0 / h), 0.0, 1.0)
    reach, values, slopes = _coverage_table(float(h), float(sigma))
    n = len(values)
    x = sd * np.float32((n - 1) / (2.0 * reach)) + np.float32((n - 1) // 2)  # table index; sd = 0: the middle
    np.clip(x, 0.0, n - 1.0, out=x)
    i = np.minimum(x.astype(np.int32), n - 2)
    x -= i
    return values[i] + x * slopes[i]


@functools.cache
def _coverage_table(h: float, sigma: float, n: int = 4097):  # n odd: sd = 0 is a sample
    """The blurred coverage sampled finely over its transition, ``reach`` mm each side (1 and 0 beyond):
    ``(reach, values, slopes to the next value)``, float32."""
    from scipy.special import ndtr

    reach = h / 2.0 + 4.5 * sigma  # beyond it the coverage is 0 or 1 to 1e-6
    s = np.linspace(-reach, reach, n)

    def g(x):
        return x * ndtr(x) + np.exp(-0.5 * x * x) * (1.0 / np.sqrt(2.0 * np.pi))

    c = np.clip((sigma / h) * (g((h / 2.0 - s) / sigma) - g((-h / 2.0 - s) / sigma)), 0.0, 1.0)
    c = 0.5 + (c - c[::-1]) / 2.0  # exactly antisymmetric about 0.5: 0.5 at sd = 0
    c[0], c[-1] = 1.0, 0.0
    return reach, c.astype(np.float32), np.append(np.diff(c), 0.0).astype(np.float32)


class Canvas:
    """Float32 HU values on a :class:`VoxelGrid`, filled with ``background`` (air, -1000 HU).

    ``h`` (mm) is the width of a voxel across a surface in :meth:`paint` (the geometric mean of
    the spacing when it is anisotropic) and ``blur`` the scanner's point-spread sigma in voxels
    (Gaussian, ``blur * h`` mm) that :meth:`paint` builds into every edge.
    """

    def __init__(self, grid: VoxelGrid, background: float = -1000.0, blur: float = 0.0):
        if not blur >= 0:
            raise ValueError(f"blur must be >= 0 (voxels), got {blur!r}")
        self.grid = grid
        self.data = np.full(grid.shape, background, dtype=np.float32)
        self.h = float(np.prod(grid.spacing)) ** (1.0 / 3.0)
        self.blur = float(blur)

    @property
    def reach(self) -> float:
        """How far (mm) outside a surface :meth:`paint` still blends: regions need this margin."""
        return self.h / 2.0 + 4.5 * self.blur * self.h

    def fill(self, reg: Region | None, where: np.ndarray, value: float) -> None:
        """Write ``value`` on the voxels of ``reg`` where the boolean ``where`` (broadcast to it) is True
        (a hard, voxel-exact edge; :meth:`paint` draws partial-volume surfaces)."""
        if reg is None:
            return
        view = self.data[reg.slices]
        view[np.broadcast_to(where, view.shape)] = value

    def paint(self, reg: Region | None, sd, value, where=None) -> None:
        """Blend ``value`` (HU, scalar or an array broadcast to ``reg``) into the voxels of ``reg`` by their
        coverage of the shape of signed distance ``sd`` (mm, < 0 inside): ``data += cover * (value - data)``
        with ``cover`` = :func:`coverage` (a ramp ``clip(0.5 - sd / h, 0, 1)`` smoothed by the scanner's
        blur), times ``where`` (bool or coverage in [0, 1]) when given, for a hard cut that is no
        visible surface. ``reg`` must reach :attr:`reach` mm beyond the shape.

        A voxel whose centre is inside (``sd < 0``) gets more than half of ``value``: it lies on the
        value's side of the half-way threshold between ``value`` and what was there.
        """
        if reg is None:
            return
        view = self.data[reg.slices]
        cover = coverage(np.broadcast_to(sd, view.shape), self.h, self.blur * self.h)
        if where is not None:
            cover = cover * where
        view += cover * (np.asarray(value, np.float32) - view)

    def to_volume(self, *, name: str, noise: float, seed: int, meta: dict) -> Volume:
        """Add Gaussian noise of ``noise`` HU (seeded; the scanner's blur is already in the edges that
        :meth:`paint` drew), round to int16 HU clipped to a CT scanner's range [-1024, 3071] and wrap
        as a CT Volume."""
        data = self.data
        if noise > 0:
            rng = np.random.default_rng(seed)
            data = data + rng.standard_normal(data.shape, dtype=np.float32) * np.float32(noise)
        out = np.clip(np.rint(data), -1024, 3071).astype(np.int16)
        return Volume(out, spacing=self.grid.spacing, affine=self.grid.affine, modality="CT", units="HU",
                      name=name, meta=meta)


def surface_point(sd_fn, start, direction, length: float, step: float = 0.05) -> np.ndarray:
    """First point (xyz mm) along the ray ``start + t * direction``, ``0 <= t <= length``, where the
    signed distance ``sd_fn(Region)`` changes sign (the surface crossing), to ``step`` mm."""
    d = np.asarray(direction, float) / np.linalg.norm(direction)
    t = np.arange(0.0, float(length), step)
    p = np.asarray(start, float)[None, :] + t[:, None] * d[None, :]
    line = Region((), p[:, 2].astype(np.float32)[:, None, None], p[:, 1].astype(np.float32)[:, None, None],
                  p[:, 0].astype(np.float32)[:, None, None])
    sd = np.asarray(sd_fn(line)).reshape(-1)
    sign = sd < 0
    change = np.flatnonzero(sign[1:] != sign[:-1])
    if change.size == 0:
        raise ValueError("the ray does not cross the surface")
    i = change[0]
    return p[i] + d * (step * sd[i] / (sd[i] - sd[i + 1]))
