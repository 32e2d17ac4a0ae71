"""Analytic test objects: a sphere, an ellipsoid and a slab, with their exact description.

Each is a homogeneous object of value ``inside`` in a background of value
``outside`` (HU, stored as int16) on a grid of ``size`` voxels per axis (or a
tuple ``(nz, ny, nx)``) at ``spacing`` mm, centred on the world origin.
The sphere's and ellipsoid's signed distance is exact / first order (``F / |grad F|``).

Sampling: by default a voxel takes ``inside`` when its *centre* lies inside the
object (sharp edges; the voxel count times the voxel volume converges to the
object's volume). With ``antialias=True`` the value is blended by an estimate of
the voxel's partial volume: a linear ramp ``clip(0.5 - sd / w, 0, 1)`` of the
signed distance ``sd`` over the voxel's width ``w`` along the surface normal
(``|nx| dx + |ny| dy + |nz| dz``), averaged over 3 x 3 x 3 sub-voxels (each with
width ``w / 3``) in the voxels the surface crosses. It is exact for an
axis-aligned plane; for a sphere of radius 5 voxels the total is within 0.3 %
of the true volume, and the isosurface at ``(inside + outside) / 2`` falls on the
true surface to a small fraction of a voxel.

``meta["truth"]`` holds the exact object (world RAS+ mm), e.g. for the sphere
``{"kind": "sphere", "center": [x, y, z], "radius": r, "inside": v1, "outside": v0}``.
"""

from __future__ import annotations

import numpy as np

from ..core import Volume
from ._canvas import VoxelGrid

__all__ = ["sphere", "ellipsoid", "slab"]

_AXES = {"x": 0, "y": 1, "z": 2}


def _grid(size, spacing) -> VoxelGrid:
    h = np.broadcast_to(np.asarray(spacing, dtype=float), (3,))  # (dz, dy, dx)
    if np.any(h <= 0):
        raise ValueError(f"spacing must be positive mm (dz, dy, dx), got {spacing!r}")
    n = (size,) * 3 if np.ndim(size) == 0 else tuple(size)
    return VoxelGrid.centred(np.array(n[::-1]) * h[::-1], tuple(n), (0.0, 0.0, 0.0))


_SUB = 3  # anti-aliasing: sub-samples per axis in a voxel that the surface crosses


def _render(grid: VoxelGrid, sd_fn, *, inside, outside, antialias, truth, name, edge=0.0) -> Volume:
    """Values from ``sd_fn(x, y, z) -> (sd, w)``: the signed distance (mm, < 0 inside) of world
    points and the voxel width along the surface normal there; wrap with ``truth``. ``edge`` > 0 (mm): a
    logistic edge ``1 / (1 + exp(sd / edge))`` instead (a scanner's blur: band-limited, thin slices or thick)."""
    reg = grid.region()
    sd, width = sd_fn(reg.x, reg.y, reg.z)
    sd = np.broadcast_to(sd, grid.shape)
    if edge > 0:
        values = outside + (inside - outside) / (1.0 + np.exp(np.clip(sd / edge, -50.0, 50.0)))
    elif antialias:
        width = np.broadcast_to(width, grid.shape)
        cover = np.clip(0.5 - sd / width, 0.0, 1.0)
        k, j, i = np.nonzero((cover > 0) & (cover < 1))  # voxels the surface crosses: average sub-voxel ramps
        offsets = (np.arange(_SUB) - (_SUB - 1) / 2.0) / _SUB
        oz, oy, ox = (o.ravel() for o in np.meshgrid(offsets, offsets, offsets, indexing="ij"))
        h = grid.spacing
        x = (reg.x.ravel()[i][:, None] + ox[None, :] * h[2]).astype(np.float32)
        y = (reg.y.ravel()[j][:, None] + oy[None, :] * h[1]).astype(np.float32)
        z = (reg.z.ravel()[k][:, None] + oz[None, :] * h[0]).astype(np.float32)
        sub_sd, _ = sd_fn(x, y, z)
        sub_cover = np.clip(0.5 - sub_sd / (width[k, j, i][:, None] / _SUB), 0.0, 1.0)
        cover = np.array(cover)
        cover[k, j, i] = sub_cover.mean(axis=1)
        values = outside + (inside - outside) * cover
    else:
        values = np.where(sd < 0, inside, outside)
    data = np.clip(np.rint(values), -32768, 32767).astype(np.int16)
    truth = dict(truth, inside=float(inside), outside=float(outside))
    meta = {"truth": truth, "antialias": bool(antialias)}
    return Volume(data, spacing=grid.spacing, affine=grid.affine, modality="CT", units="HU", name=name, meta=meta)


def _normal_width(grid: VoxelGrid, nx, ny, nz):
    dz, dy, dx = grid.spacing
    return np.abs(nx) * dx + np.abs(ny) * dy + np.abs(nz) * dz


def ellipsoid(size=64, *, semi_axes=(25.0, 18.0, 12.0), center=(0.0, 0.0, 0.0), inside=1000.0,
              outside=-1000.0, spacing=1.0, antialias=False) -> Volume:
    """An axis-aligned ellipsoid of semi-axes ``(a, b, c)`` mm along world x, y, z.

    ``meta["truth"] = {"kind": "ellipsoid", "center": [x, y, z], "semi_axes": [a, b, c],
    "volume": 4/3 pi a b c (mm^3), "inside", "outside"}``. Sharp sampling uses the
    exact inside test; anti-aliasing uses the first-order distance ``F / |grad F|``.
    """
    a, b, c = (float(s) for s in semi_axes)
    if min(a, b, c) <= 0:
        raise ValueError(f"semi_axes must be positive mm, got {semi_axes!r}")
    grid = _grid(64 if size is None else size, spacing)
    cx, cy, cz = (float(v) for v in center)

    def sd_fn(x, y, z):
        ux, uy, uz = (x - cx) / a, (y - cy) / b, (z - cz) / c
        gx, gy, gz = ux / a, uy / b, uz / c  # half the gradient of F = ux^2 + uy^2 + uz^2 - 1
        norm = np.maximum(np.sqrt(gx * gx + gy * gy + gz * gz), 1e-12)
        sd = (ux * ux + uy * uy + uz * uz - 1.0) / (2.0 * norm)
        return sd, _normal_width(grid, gx / norm, gy / norm, gz / norm)

    truth = {"kind": "ellipsoid", "center": [cx, cy, cz], "semi_axes": [a, b, c],
             "volume": 4.0 / 3.0 * np.pi * a * b * c}
    return _render(grid, sd_fn, inside=inside, outside=outside, antialias=antialias, truth=truth,
                   name="ellipsoid")


def sphere(size=64, *, radius=20.0, center=(0.0, 0.0, 0.0), inside=1000.0, outside=-1000.0, spacing=1.0,
           antialias=False, edge=0.0) -> Volume:
    """A sphere of ``radius`` mm around ``center`` (world xyz mm); ``edge`` > 0 (mm): a logistic edge of that
    width (blurred as a scanner blurs, and sampled as finely or coarsely as ``spacing`` says: a thick-slice scan
    of a smooth wall, the phantom of trilinear reconstruction's terraces).

    ``meta["truth"] = {"kind": "sphere", "center": [x, y, z], "radius": r,
    "volume": 4/3 pi r^3 (mm^3), "inside", "outside"}``.
    """
    r = float(radius)
    if r <= 0:
        raise ValueError(f"radius must be positive mm, got {radius!r}")
    grid = _grid(64 if size is None else size, spacing)
    cx, cy, cz = (float(v) for v in center)

    def sd_fn(x, y, z):
        px, py, pz = x - cx, y - cy, z - cz
        dist = np.sqrt(px * px + py * py + pz * pz)
        safe = np.maximum(dist, 1e-12)
        return dist - r, _normal_width(grid, px / safe, py / safe, pz / safe)

    truth = {"kind": "sphere", "center": [cx, cy, cz], "radius": r, "volume": 4.0 / 3.0 * np.pi * r**3}
    return _render(grid, sd_fn, inside=inside, outside=outside, antialias=antialias, truth=truth, name="sphere",
                   edge=float(edge))


def slab(size=64, *, thickness=20.0, axis="z", center=(0.0, 0.0, 0.0), inside=1000.0, outside=-1000.0,
         spacing=1.0, antialias=False) -> Volume:
    """A homogeneous slab of ``thickness`` mm across world ``axis`` ("x", "y" or "z"), infinite along the others.

    ``meta["truth"] = {"kind": "slab", "axis": "z", "normal": [0, 0, 1], "center": [x, y, z],
    "thickness": L, "inside", "outside"}``: the slab is ``|(p - center) . normal| < L / 2``.
    """
    if axis not in _AXES:
        raise ValueError(f"axis must be one of {sorted(_AXES)}, got {axis!r}")
    L = float(thickness)
    if L <= 0:
        raise ValueError(f"thickness must be positive mm, got {thickness!r}")
    grid = _grid(64 if size is None else size, spacing)
    a = _AXES[axis]
    c0 = float(center[a])
    width = np.float32(grid.spacing[2 - a])

    def sd_fn(x, y, z):
        return np.abs((x, y, z)[a] - c0) - L / 2.0, width

    normal = [0.0, 0.0, 0.0]
    normal[a] = 1.0
    truth = {"kind": "slab", "axis": axis, "normal": normal, "center": [float(c) for c in center], "thickness": L}
    return _render(grid, sd_fn, inside=inside, outside=outside, antialias=antialias, truth=truth, name="slab")
