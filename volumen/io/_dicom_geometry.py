"""DICOM slice headers -> voxel geometry: order the slices along their normal, build affine and spacing.

Geometry is computed in DICOM's patient LPS+ space and turned into RAS+ once,
in :func:`measure`, by negating the x and y rows of the affine.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..errors import SeriesError
from ._dicom_series import SliceHeader

__all__ = ["Geometry", "measure"]

_LPS_TO_RAS = np.diag([-1.0, -1.0, 1.0, 1.0])
_SAME_ORIENTATION = 1e-4     # max difference of direction cosines within one series
_DUPLICATE_MM = 1e-3         # slices closer than this along the normal share a position
_UNIFORM_MM, _UNIFORM_REL = 0.01, 0.01  # a gap may differ from the mean by max(0.01 mm, 1 %)


@dataclass
class Geometry:
    """Slice order and voxel geometry of a series.

    ``order[k]`` is the index (into the series' slice list) of data slice ``k``;
    ``positions`` (n,) mm are the slices' positions along the slice normal, ascending;
    ``affine`` maps (i, j, k, 1) = (column, row, slice) to RAS+ mm; ``spacing`` is
    ``(dz, dy, dx)`` mm, the norms of the affine's k, j, i columns.
    """

    order: np.ndarray
    positions: np.ndarray
    affine: np.ndarray
    spacing: tuple[float, float, float]
    uniform: bool
    normal_lps: np.ndarray
    warnings: list[str]
    tilt_deg: float = 0.0


def _check_same(slices: list[SliceHeader], key, what: str, where, close=None) -> None:
    first = key(slices[0])
    for s in slices[1:]:
        v = key(s)
        same = v == first if close is None else close(v, first)
        if not same:
            raise SeriesError(where, f"mixed {what} in one series: {first} in {slices[0].label()} but {v} in "
                                     f"{s.label()}")


def measure(slices: list[SliceHeader], where) -> Geometry:
    """Order ``slices`` along their normal and compute affine (RAS+) and spacing.

    The normal is ``row cosine x column cosine`` (ImageOrientationPatient); slices are
    sorted by ImagePositionPatient projected on it. The k column of the affine is
    ``(position of the last slice - position of the first) / (n - 1)``, so gantry tilt
    and oblique stacks are kept. Raises :class:`SeriesError` for mixed sizes,
    orientations or pixel spacings, missing positions and duplicate positions.
    """
    notes: list[str] = []
    n = len(slices)
    _check_same(slices, lambda s: "x".join(map(str, s.shape[::-1])), "image sizes (columns x rows)", where)
    if any(s.orientation is None for s in slices) or any(s.position is None for s in slices):
        if n > 1:
            bad = next(s for s in slices if s.orientation is None or s.position is None)
            raise SeriesError(where, f"{bad.label()} has no ImagePositionPatient / ImageOrientationPatient, "
                                     f"so the {n} slices cannot be ordered")
        notes.append("no ImagePositionPatient / ImageOrientationPatient: assumed an axial slice at the origin")
        slices = [replace(slices[0], position=slices[0].position or (0.0, 0.0, 0.0),
                          orientation=slices[0].orientation or (1.0, 0.0, 0.0, 0.0, 1.0, 0.0))]
    _check_same(slices, lambda s: tuple(round(v, 6) for v in s.orientation), "orientations (ImageOrientationPatient)",
                where, lambda a, b: np.allclose(a, b, atol=_SAME_ORIENTATION))
    _check_same(slices, lambda s: s.pixel_spacing, "pixel spacings (PixelSpacing)", where,
                lambda a, b: (a is None and b is None) or (a is not None and b is not None
                                                           and np.allclose(a, b, rtol=1e-4)))
    iop = np.asarray(slices[0].orientation, float)
    row_dir, col_dir = iop[:3] / np.linalg.norm(iop[:3]), iop[3:] / np.linalg.norm(iop[3:])
    normal = np.cross(row_dir, col_dir)
    if np.linalg.norm(normal) < 0.5:
        raise SeriesError(where, f"ImageOrientationPatient {tuple(iop)} has parallel row and column directions")
    normal /= np.linalg.norm(normal)
    notes.extend(dict.fromkeys(n for s in slices for n in s.notes))  # each distinct note once, in order
    if slices[0].pixel_spacing is None and not any("pixels" in n for n in notes):
        notes.append("no PixelSpacing: assumed 1 mm x 1 mm pixels")
    dy, dx = slices[0].pixel_spacing or (1.0, 1.0)
    ipp = np.array([s.position for s in slices], float)
    proj = ipp @ normal
    order = np.argsort(proj, kind="stable")
    pos, ipp = proj[order], ipp[order]
    gaps = np.diff(pos)
    dup = np.flatnonzero(gaps < _DUPLICATE_MM)
    if dup.size:
        a, b = slices[order[dup[0]]], slices[order[dup[0] + 1]]
        raise SeriesError(where, f"{dup.size} slice(s) share a position with another, e.g. {a.label()} and "
                                 f"{b.label()} at {pos[dup[0]]:.3f} mm along the slice normal; a series holding "
                                 "several time points, echoes or stacks is not one volume (no slice was dropped)")
    uniform, tilt = True, 0.0
    if n == 1:
        dz = slices[0].thickness if slices[0].thickness and slices[0].thickness > 0 else 1.0
        notes.append(f"single-slice series: slice spacing taken as {dz:g} mm "
                     f"({'SliceThickness' if slices[0].thickness else 'assumed'})")
        k_col = normal * dz
    else:
        k_col = (ipp[-1] - ipp[0]) / (n - 1)
        mean = (pos[-1] - pos[0]) / (n - 1)
        tol = max(_UNIFORM_MM, _UNIFORM_REL * mean)
        if np.any(np.abs(gaps - mean) > tol):
            uniform = False
            notes.append(f"non-uniform slice spacing: gaps between {gaps.min():.4g} and {gaps.max():.4g} mm along "
                         f"the slice normal (mean {mean:.4g} mm); loaded as is: the affine uses the mean spacing, "
                         "the true positions are in meta['slice_positions']; load with resample=True for a "
                         "uniform grid")
        cosang = abs(float(k_col @ normal)) / np.linalg.norm(k_col)
        tilt = float(np.degrees(np.arccos(min(cosang, 1.0))))
        if tilt > 0.01:
            notes.append(f"slices are sheared (gantry tilt of {tilt:.2f} degrees); the affine keeps the shear")
        # positions off the line from the first to the last slice
        t = (pos - pos[0]) / (pos[-1] - pos[0])
        off = np.linalg.norm(ipp - (ipp[0] + t[:, None] * (ipp[-1] - ipp[0])), axis=1).max()
        if off > max(0.01, 0.01 * min(dx, dy)):
            notes.append(f"slice positions are not on one line (up to {off:.3g} mm off); the affine uses the "
                         "first and the last slice")
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = row_dir * dx, col_dir * dy, k_col, ipp[0]
    affine = _LPS_TO_RAS @ m
    spacing = (float(np.linalg.norm(k_col)), float(dy), float(dx))
    return Geometry(order, pos, affine, spacing, uniform, normal, notes, tilt)
