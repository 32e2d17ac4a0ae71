"""Rays cast from a point inside a lumen: how far each stays in the lumen's values, and what it meets then.

:func:`cast_rays` samples the data along evenly spread directions (a Fibonacci
lattice) from a point, out to ``reach`` mm, on a copy of the point's neighbourhood
smoothed by a Gaussian of half a voxel (enough to quiet the noise, so one sample
does not pass for a wall, and little enough to keep a wall one voxel thick
visible). Along each ray:

* the ray *leaves* the lumen at the first sample farther than ``tolerance`` from
  the lumen's value (up: a brighter wall, as round air; down: a darker one, as
  round contrast);
* what it *meets* is the value where the edge it climbed levels off: the first
  turning point of the profile (the crest of a thin wall), or the first shoulder,
  where the slope falls to half its steepest (a plateau of wall tissue, even one
  a few voxels thick in front of a darker neighbour such as a lung).

Rays that stay in the lumen's values to ``reach`` (along a tube) or leave the
scan meet nothing.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["RayProbe", "cast_rays", "RAYS"]

#: directions cast: a Fibonacci lattice of this many leaves about 16 degrees between neighbours, so a wall
#: patch a fifth of a lumen's circumference across is met by several rays
RAYS = 162


@dataclass(frozen=True)
class RayProbe:
    """What the rays from a point met.

    Attributes
    ----------
    directions : (n, 3) float
        Unit world directions.
    hit : (n,) bool
        Whether the ray left the lumen's values within reach.
    distance : (n,) float, mm
        Where it left them (inf when it did not).
    sign : (n,) int
        +1: it met brighter values, -1: darker, 0: nothing.
    met : (n,) float, data units
        The value met (NaN when nothing was).
    inside : (m, 3) int
        The voxels ``(z, y, x)`` the rays crossed more than a voxel before they left the lumen's values (the
        lumen round the point, its partial-volume edge left out).
    """

    directions: np.ndarray
    hit: np.ndarray
    distance: np.ndarray
    sign: np.ndarray
    met: np.ndarray
    inside: np.ndarray


def _box(volume, zyx, reach: float):
    sp = np.asarray(volume.spacing, float)
    r = np.ceil(reach / sp).astype(int) + 2
    lo = np.maximum(np.asarray(zyx) - r, 0)
    hi = np.minimum(np.asarray(zyx) + r + 1, volume.shape)
    return lo, np.asarray(volume.data[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]], np.float32)


def _profiles(volume, zyx, reach: float, directions: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """Samples ``(n_rays, n_samples)`` along each direction every half of the smallest voxel (NaN where the ray
    has left the scan), their voxels ``(n_rays, n_samples, 3)`` (z, y, x) and the step (mm)."""
    from scipy import ndimage

    lo, box = _box(volume, zyx, reach)
    box = ndimage.gaussian_filter(box, 0.5, mode="nearest")  # half a voxel: noise down by ~2.4, thin walls kept
    step = 0.5 * float(min(volume.spacing))
    t = np.arange(0.0, reach + 1e-9, step)
    origin = volume.index_to_world(np.asarray(zyx, float)[::-1])
    pts = origin[None, None, :] + t[None, :, None] * directions[:, None, :]
    ijk = volume.world_to_index(pts.reshape(-1, 3))
    zyx_local = ijk[:, ::-1] - lo
    inside = np.all((zyx_local >= 0) & (zyx_local <= np.array(box.shape) - 1), axis=1)
    vals = ndimage.map_coordinates(box, zyx_local.T, order=1, mode="nearest")
    vals = np.where(inside, vals, np.nan).reshape(len(directions), len(t))
    voxels = np.clip(np.rint(ijk[:, ::-1]).astype(int), 0, np.array(volume.shape) - 1)
    return vals, voxels.reshape(len(directions), len(t), 3), step


def _met(profile: np.ndarray, j0: int, sign: int) -> float:
    """The value where the edge climbed from sample ``j0`` (in direction ``sign``) levels off."""
    p = sign * profile[j0:]
    p = p[np.isfinite(p)]
    if p.size < 3:
        return float(sign * p[-1]) if p.size else float("nan")
    g = np.gradient(p)
    top = int(np.argmax(g[:8]))  # the edge's steepest point: within 4 voxels (8 samples) of where the ray left
    for j in range(top + 1, g.size):
        if g[j] <= 0.0 or (g[j] < 0.5 * g[top] and j + 1 < g.size and g[j] <= g[j + 1]):
            return float(sign * p[j])
    return float(sign * p[-1])


def cast_rays(volume, zyx, lumen: float, tolerance: float, reach: float) -> RayProbe:
    """Cast :data:`RAYS` rays from voxel ``zyx`` (``(z, y, x)``) out to ``reach`` mm.

    Parameters
    ----------
    volume : Volume
    zyx : (3,) int
        The voxel the rays start from.
    lumen : float, data units
        The lumen's value (its median near the point).
    tolerance : float, data units
        How far from ``lumen`` a sample may be and still count as lumen (a few noise standard deviations).
    reach : float, mm

    Returns
    -------
    RayProbe
    """
    from ..wall._first_hit import fibonacci_directions

    dirs = fibonacci_directions(RAYS)
    prof, voxels, step = _profiles(volume, zyx, reach, dirs)
    n = len(dirs)
    hit = np.zeros(n, bool)
    dist = np.full(n, np.inf)
    sign = np.zeros(n, int)
    met = np.full(n, np.nan)
    dev = np.abs(np.nan_to_num(prof, nan=lumen) - lumen)
    before = np.isfinite(prof)
    margin = int(np.ceil(float(max(volume.spacing)) / step))  # samples in one voxel
    for k in range(n):
        out = np.flatnonzero(dev[k] > tolerance)
        if out.size == 0:
            continue
        j0 = int(out[0])
        before[k, max(j0 - margin, 0):] = False
        s = 1 if prof[k, j0] > lumen else -1
        hit[k], dist[k], sign[k] = True, j0 * step, s
        met[k] = _met(prof[k], max(j0 - 1, 0), s)
    return RayProbe(dirs, hit, dist, sign, met, np.unique(voxels[before], axis=0))
