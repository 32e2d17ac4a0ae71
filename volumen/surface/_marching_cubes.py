"""Marching cubes: the public function (checks, allocation, geometry); kernels in ``_mc_rows``, ``_mc_kernel``."""

from __future__ import annotations

import numpy as np

from ..core import Volume
from ._mesh import Mesh

__all__ = ["marching_cubes"]

#: dtypes the kernel reads as they are (each sample as its float32 value); others are converted to float32
NATIVE_DTYPES = tuple(np.dtype(t) for t in ("int16", "uint16", "uint8", "float32"))


def _geometry(volume, spacing) -> tuple[np.ndarray, np.ndarray]:
    """Data array ``[z, y, x]`` and the 4x4 voxel (i, j, k) -> world mm affine."""
    if isinstance(volume, Volume):
        if spacing is not None:
            raise ValueError("spacing is given by the Volume; pass spacing only with a plain array")
        return volume.data, np.asarray(volume.affine, dtype=np.float64)
    data = np.asarray(volume)
    sp = (1.0, 1.0, 1.0) if spacing is None else tuple(float(s) for s in np.ravel(spacing))
    if len(sp) != 3 or not all(np.isfinite(sp)) or min(sp) <= 0:
        raise ValueError(f"spacing must be three positive mm values (dz, dy, dx), got {spacing}")
    return data, np.diag([sp[2], sp[1], sp[0], 1.0])


def _kernel_array(data: np.ndarray) -> np.ndarray:
    """The samples as the kernel reads them: the array itself (C order) when its dtype is one the kernel is
    compiled for, booleans as uint8 (a view), anything else as a float32 copy."""
    if data.dtype == np.bool_:
        data = data.view(np.uint8)
    if data.dtype not in NATIVE_DTYPES:
        return np.ascontiguousarray(data, dtype=np.float32)
    return np.ascontiguousarray(data)


def marching_cubes(volume, level: float | None = None, *, spacing=None, mask=None, step: int = 1,
                   voxel_coordinates: bool = True) -> Mesh:
    """Isosurface of a scalar volume or a binary mask as a watertight indexed mesh.

    Parameters
    ----------
    volume : Volume or (nz, ny, nx) array
        Samples indexed ``[z, y, x]``. A :class:`~volumen.core.Volume` brings its affine
        (voxel ``(i, j, k)`` -> world RAS+ mm); a plain array is placed with ``spacing``
        and voxel (0, 0, 0) at the origin. Boolean arrays are meshed at level 0.5.
    level : float, optional
        Iso level in the data's units (HU for CT). Values above it are *inside*.
        Default: 0.5 for a mask (bool data or only 0 and 1), else the middle of the range.
    spacing : (3,) float, mm, optional
        ``(dz, dy, dx)`` for a plain array; not allowed with a Volume.
    mask : (nz, ny, nx) bool array or Volume, optional
        Only cubes whose first corner ``[z, y, x]`` is True make triangles; the surface
        is open where it leaves the mask.
    step : int
        Sample every ``step``-th voxel on each axis (coarser, faster mesh).
    voxel_coordinates : bool
        Also return the vertices as voxel indices (``Mesh.voxel_vertices``); False saves
        memory and about a tenth of the time.

    Returns
    -------
    Mesh
        ``vertices`` (N, 3) float32 world mm; ``faces`` (M, 3) int32 wound
        counter-clockwise seen from outside (from the lower values); ``normals`` (N, 3)
        float32, the negated, normalised gradient (central differences, spacing and
        orientation from the affine), pointing outward; ``voxel_vertices`` (N, 3)
        float32 fractional voxel indices ``(i, j, k)`` (None unless ``voxel_coordinates``).
        One vertex per crossed grid edge, plus one inside the few cubes whose contour is
        a loop that cannot be triangulated without an edge on a cube face. No two vertices
        share a position: a crossing is kept a thousandth of a voxel off the grid points
        (samples equal to the level are outside; see ``_mc_kernel.T_MIN``), so a file
        format that joins corners by position (STL) gets the same closed mesh.

    Notes
    -----
    Ambiguous cube faces are decided by the asymptotic decider on the face's four values,
    identically from both cubes sharing it, with tables that keep every mesh edge shared by
    exactly two triangles wherever the surface is closed (see ``_mc_tablegen.py``). The
    passes follow VTK's flying edges: per-row edge counts and trims (the stretch of a row
    holding its crossings), prefix sums, then parallel generation of shared vertices and
    triangles, each thread taking a run of rows of balanced work; inside flags are scanned
    eight samples at a time and only inside the trims. int16, uint16, uint8 (and bool) and
    float32 data are read as they are, each sample as its float32 value; other dtypes are
    converted to float32 first.

    References
    ----------
    Schroeder, W., Maynard, R. and Geveci, B. "Flying edges: a high-performance scalable
    isocontouring algorithm", IEEE LDAV 2015.
    """
    data, affine, is_mask, step = _checked(volume, spacing, step)
    vol = _kernel_array(data)
    if level is None:  # the default needs the range before the pass: one more reduction
        lo_v, hi_v = float(vol.min()), float(vol.max())
        is_mask = is_mask or (lo_v >= 0 and hi_v <= 1 and data.dtype.kind in "biu")
        level = 0.5 if is_mask else 0.5 * (lo_v + hi_v)
    level = float(level)
    rows = _sign_pass(vol, level)
    m = _mask_array(mask, volume, step)
    aff = affine @ np.diag([step, step, step, 1.0])
    flip = bool(np.linalg.det(aff[:3, :3]) < 0)
    xyz, nrm, ijk, faces = _mesh_passes(vol, np.float32(level), rows, m, aff, flip, voxel_coordinates)
    if step > 1:
        ijk *= step
    if mask is not None:
        xyz, faces, nrm, *rest = _drop_unused(xyz, faces, nrm, *([ijk] if voxel_coordinates else []))
        ijk = rest[0] if voxel_coordinates else ijk
    mesh = Mesh.__new__(Mesh)  # the kernel's output is valid by construction: skip re-checks
    mesh.vertices, mesh.faces, mesh.normals = xyz, faces, nrm
    mesh.voxel_vertices = ijk if voxel_coordinates else None
    mesh.meta = {"level": level, "step": step}
    return mesh


def _checked(volume, spacing, step):
    """``(data, affine, is_mask, step)``: the samples every ``step``-th voxel, their affine, whether they are
    boolean, and ``step`` as an int; ValueError on a bad shape or step."""
    data, affine = _geometry(volume, spacing)
    if data.ndim != 3:
        raise ValueError(f"marching_cubes needs a 3-D [z, y, x] array, got shape {data.shape}")
    step = int(step)
    if step < 1:
        raise ValueError(f"step must be a positive integer, got {step}")
    is_mask = data.dtype == np.bool_
    if step > 1:
        data = data[::step, ::step, ::step]
    if min(data.shape) < 2:
        raise ValueError(f"marching_cubes needs at least 2 samples per axis, got shape {data.shape}")
    return data, affine, is_mask, step


def _mask_array(mask, volume, step: int) -> np.ndarray:
    """The cube mask as the kernel takes it (a 1-voxel dummy when there is none)."""
    if mask is None:
        return np.zeros((1, 1, 1), np.bool_)
    m = mask.data if isinstance(mask, Volume) else np.asarray(mask)
    if m.shape != np.asarray(volume.data if isinstance(volume, Volume) else volume).shape:
        raise ValueError(f"mask shape {m.shape} differs from the volume's")
    return np.ascontiguousarray(m[::step, ::step, ::step], dtype=np.bool_)


def _sign_pass(vol: np.ndarray, level: float) -> dict:
    """Pass 1 (see ``_mc_rows``): the flag rows and per-row counts; ValueError on NaN or a level out of range."""
    from ._mc_records import Sign, SignOut
    from ._mc_rows import run_pass, sign_rows, threshold

    nz, ny, nx = vol.shape
    nrows = nz * ny
    thr = threshold(vol.dtype, level)
    if thr is None:  # beyond the dtype's range, so beyond the data's
        _check_range(vol, level)
    sgn = np.empty((nrows + 2, 8 * ((nx + 7) // 8)), np.uint8)  # flag rows in whole 64-bit words
    sgn[nrows:] = 0  # the shared rows all outside and all inside
    sgn[nrows + 1, :nx] = 1
    rows = dict(words=sgn.view(np.uint64), nxc=np.empty(nrows, np.int64), trim=np.empty((nrows, 4), np.int64))
    ninside = np.empty(nrows, np.int64)
    nbad = np.empty(nrows, np.int64)
    bits = vol.view(np.uint32) if vol.dtype == np.float32 else np.empty((0, 0, 0), np.uint32)
    run_pass(sign_rows, np.full(nrows, nx), (Sign(vol, thr, sgn, rows["words"], bits),),
             (SignOut(rows["nxc"], rows["trim"], ninside, nbad),))
    if nbad.any():
        raise ValueError("marching_cubes: the volume holds NaN or infinite values")
    if ninside.sum() in (0, vol.size):  # no sample above the level, or none at or below: is it in range?
        _check_range(vol, level)
    return rows


def _check_range(vol: np.ndarray, level: float) -> None:
    lo_v, hi_v = float(vol.min()), float(vol.max())
    if not lo_v <= level <= hi_v:
        raise ValueError(f"level {level:g} is outside the data range [{lo_v:g}, {hi_v:g}]")


def _mesh_passes(vol, lvl, rows, m, aff, flip: bool, voxel_coordinates: bool):
    """Passes 2 and 3 (counts, prefix sums, vertices and triangles): ``(xyz, nrm, ijk, faces)``."""
    from . import _mc_kernel as K
    from ._mc_records import Counts, Emit, Grid, Out
    from ._mc_rows import count_costs, emit_costs, run_pass, running_sums

    nz, ny, nx = vol.shape
    words, nxc, trim = rows["words"], rows["nxc"], rows["trim"]
    nyc, nzc = np.empty_like(nxc), np.empty_like(nxc)
    ntri = np.empty((nz - 1) * (ny - 1), np.int64)  # pass 2 writes every cube row's
    ncen = np.empty_like(ntri)
    grid = Grid(vol, lvl, words, trim, m, m.size > 1)
    span, cost = count_costs(trim, nxc)
    run_pass(K.count_rows, cost, (grid,), (Counts(nyc, nzc, ntri, ncen),))
    per_row, cost = emit_costs(span, nxc, nyc, nzc, ntri, nz, ny)
    vbase = running_sums(per_row, 0)  # each with the total appended
    cbase = running_sums(ncen, vbase[-1])  # centre vertices numbered after the edge vertices
    tbase = running_sums(ntri, 0)
    n_vert, n_tri = int(cbase[-1]), int(tbase[-1])
    ijk = np.empty((n_vert if voxel_coordinates else 0, 3), np.float32)
    xyz = np.empty((n_vert, 3), np.float32)
    nrm = np.empty((n_vert, 3), np.float32)
    faces = np.empty((n_tri, 3), np.int32)
    nmat = np.linalg.inv(aff[:3, :3]).T.copy()
    run_pass(K.emit_rows, cost, (grid,),
             (Emit(nxc, nyc, vbase[:-1], tbase[:-1], cbase[:-1], aff, nmat, flip), Out(ijk, xyz, nrm, faces)),
             scratch=13)
    return xyz, nrm, ijk, faces


def _drop_unused(xyz, faces, *per_vertex):
    """Remove vertices no face uses (those on edges of masked-out cubes) and renumber faces."""
    used = np.zeros(len(xyz), np.bool_)
    used[faces.ravel()] = True
    new_index = np.cumsum(used, dtype=np.int64) - 1
    faces = new_index[faces].astype(np.int32)
    return (xyz[used], faces, *(a[used] for a in per_vertex))
