"""Cross-sections of a lumen orthogonal to its centerline: area, diameters and the inscribed sphere.

At each centerline point the plane through it orthogonal to the path (spanned by the rotation-minimizing
normal and binormal of :meth:`~volumen.endoscopy.Centerline.frames`) is sampled on a square of pixels
:data:`PIXEL` voxels across, wide enough for :data:`HALF_WIDTH` local radii (widened while the section
touches its edge). The section is the connected region of the plane holding the centerline point (the
one nearest it where the point itself falls outside): a plane that cuts the tube again further along a
bend, or a neighbouring vessel, is not counted.

* **Which pixels are lumen.** Given a segmentation, the mask smoothed (:data:`MASK_SMOOTH`), sampled
  trilinearly and cut at one half (the wall half-way between voxel centres). Grown from the data, the
  data decide at each section (``refine``): the threshold is half-way between the lumen's own value
  there (the median of the section a voxel in from its edge) and the wall's (the median of a ring
  1.5-3 voxels outside it, other lumens left out; round an air lumen the crest of its thin wall, the
  99.5th percentile of a ring 0.5-2 voxels out, the scan sampled there from cubic B-splines), the full
  width at half maximum of the vessel's edge,
  so contrast that fades along the vessel, or layers across it, does not move the wall as one global
  threshold does.
* **Area, equivalent diameter**: pixels times their area; the diameter of the disc of that area.
* **Minimum and maximum diameter** (Feret's): the narrowest and widest extent of the section over
  directions every :data:`ANGLE_STEP` degrees, each with its direction (a world unit vector in the plane).
* **Maximum inscribed sphere radius**: the largest distance to the wall (:class:`._inscribed.WallDistance`)
  over the section.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Sections", "measure_sections", "PIXEL", "HALF_WIDTH"]

#: section pixels are this fraction of the smallest voxel spacing
PIXEL = 0.25
#: the section's square reaches this many local radii from the centerline (and 4 voxels more) at least
HALF_WIDTH = 2.5
#: the inscribed sphere's centre is looked for at this many pixels of a section at most
CANDIDATES = 400
#: Feret's diameters are measured over directions this many degrees apart
ANGLE_STEP = 1.0
#: ... on the section's outline smoothed by a Gaussian of this many voxels
OUTLINE_SMOOTH = 0.5
#: a mask is smoothed by a Gaussian of this many (smallest) voxel spacings before it is cut at one half: its
#: staircase would otherwise widen the widest extent of a section along the diagonals
MASK_SMOOTH = 0.7
#: the wall's ring round the section, voxels from its edge: its median is the wall's value round a contrast lumen
RING = (1.5, 3.0)
#: round an air lumen the wall is a thin crest between the air and the air-like lung: its value is this
#: percentile of the ring this many voxels from the section's edge
CREST, CREST_RING = 99.5, (0.5, 2.0)
#: the section is drawn again at its half-way value this many times at most, each reaching at most
#: :data:`REACH` voxels past the last (a grown lumen that missed a dim layer of contrast is caught up)
REFINE_STEPS = 4
#: a section still touching the square's edge at this many local radii is cut there (a plane along a bend
#: that lies in the lumen for centimetres)
MAX_HALF_RADII = 8.0
REACH = 2.0
#: round an air lumen the scan is sampled from cubic B-splines (trilinear samples between the voxel centres
#: blunt the crest of a wall one or two voxels thick, and the half-way value with it, by tens of HU), on the
#: lumen's box widened by this many voxels (past the farthest a section is drawn again)
CUBIC_PAD = 12


@dataclass(frozen=True, eq=False)
class Sections:
    """The cross-sections along a centerline, one row per point: ``area`` (mm^2), ``diameter`` (equivalent,
    mm), ``min_diameter`` and ``max_diameter`` (mm) with their directions (N, 3) world unit vectors,
    ``inscribed_radius`` (mm), ``threshold`` (the data value the wall was drawn at; NaN from a mask),
    ``centroid`` (N, 3) world mm, the centre of the section's area; ``sign`` +1 where the lumen is brighter
    than its wall (contrast), -1 where darker (air)."""

    area: np.ndarray
    diameter: np.ndarray
    min_diameter: np.ndarray
    max_diameter: np.ndarray
    min_direction: np.ndarray
    max_direction: np.ndarray
    inscribed_radius: np.ndarray
    threshold: np.ndarray
    centroid: np.ndarray
    sign: float = 1.0


def _plane(volume, point, normal, binormal, half: float, pixel: float):
    """Voxel coordinates ``[z, y, x]`` (3, n, n) of the square of pixels ``half`` mm round ``point`` in the plane."""
    m = int(np.ceil(half / pixel))
    u = np.arange(-m, m + 1) * pixel  # the point at the middle pixel
    uu, vv = np.meshgrid(u, u, indexing="ij")
    world = point + uu[..., None] * normal + vv[..., None] * binormal
    ijk = volume.world_to_index(world.reshape(-1, 3))
    return ijk[:, ::-1].T.reshape(3, len(u), len(u))


def _sample(array, coords, order: int = 1) -> np.ndarray:
    """Samples (float32; trilinear, or of ``order`` 3 from B-spline coefficients) of ``array`` at voxel
    coordinates ``coords`` (3, ...); 0 outside it."""
    from scipy import ndimage

    return ndimage.map_coordinates(array, coords, order=order, mode="constant", cval=0.0, output=np.float32,
                                   prefilter=False)


@dataclass(frozen=True, eq=False)
class _Fields:
    """What every section samples: the smoothed ``lumen`` mask on its box (from voxel ``offset``), the
    :class:`WallDistance` ``distance``, the scan's ``values`` (None: the mask decides the wall; B-spline
    coefficients of the scan on a box from voxel ``values_offset`` round an air lumen, see :data:`CUBIC_PAD`)
    and ``sign`` (+1: the lumen is brighter than its wall)."""

    lumen: np.ndarray
    offset: np.ndarray
    distance: object
    values: np.ndarray | None
    sign: float
    values_offset: np.ndarray

    def lumen_at(self, coords: np.ndarray) -> np.ndarray:
        return _sample(self.lumen, coords - self.offset.reshape(3, 1, 1))

    def values_at(self, coords: np.ndarray) -> np.ndarray:
        cubic = self.sign < 0
        return _sample(self.values, coords - self.values_offset.reshape(3, 1, 1), 3 if cubic else 1)


def _component(inside: np.ndarray) -> np.ndarray:
    """The connected region of ``inside`` holding the square's centre, or the one nearest it."""
    from scipy import ndimage

    labels, n = ndimage.label(inside)
    if n == 0:
        return inside
    c = inside.shape[0] // 2
    pick = labels[c, c]
    if pick == 0:
        ij = np.argwhere(labels > 0)
        pick = labels[tuple(ij[int(np.argmin(np.sum((ij - c) ** 2, axis=1)))])]
    return labels == pick


def _refined(section, others, values, sign: float, voxel: float, pixel: float):
    """The section drawn again at the half-way value between its lumen's and its wall's (see the module
    docstring); returns ``(section, threshold)``, the section as it was where either is not measurable."""
    from scipy import ndimage

    depth = ndimage.distance_transform_edt(section) * pixel
    away = ndimage.distance_transform_edt(~section) * pixel
    core = values[depth >= voxel]
    ring, crest = RING if sign > 0 else CREST_RING, 50.0 if sign > 0 else CREST
    ring = values[(away >= ring[0] * voxel) & (away <= ring[1] * voxel) & ~others]
    if core.size < 4 or ring.size < 4:
        return section, np.nan
    threshold = 0.5 * (float(np.median(core)) + float(np.percentile(ring, crest)))
    near = away <= REACH * voxel
    grown = ndimage.binary_fill_holes(near & (sign * (values - threshold) > 0))
    return _component(grown), threshold


def _feret(section: np.ndarray, pixel: float, voxel: float, normal, binormal):
    """Minimum and maximum extent (mm) of the section over directions, with their world directions: the
    extents of its outline (:func:`skimage.measure.find_contours`, sub-pixel) once smoothed by a Gaussian
    of :data:`OUTLINE_SMOOTH` voxels, so that the wall's noise does not widen the widest extent."""
    from scipy import ndimage
    from skimage.measure import find_contours

    smooth = ndimage.gaussian_filter(np.pad(section, 2).astype(np.float32), OUTLINE_SMOOTH * voxel / pixel)
    outline = find_contours(smooth, 0.5)
    if not outline:
        return 0.0, 0.0, normal, normal
    ij = np.concatenate(outline) * pixel
    theta = np.deg2rad(np.arange(0.0, 180.0, ANGLE_STEP))
    proj = ij @ np.stack([np.cos(theta), np.sin(theta)])
    extent = proj.max(axis=0) - proj.min(axis=0)
    lo, hi = int(np.argmin(extent)), int(np.argmax(extent))
    direction = [np.cos(theta[k]) * normal + np.sin(theta[k]) * binormal for k in (lo, hi)]
    return float(extent[lo]), float(extent[hi]), direction[0], direction[1]


def _inscribed(dist, coords, section: np.ndarray, voxel: float) -> float:
    """The largest distance to the wall over the section (``voxel`` in pixels): measured at its pixels within
    a voxel and a half of the deepest in the plane (the sphere's centre lies there), at most
    :data:`CANDIDATES` of them."""
    from scipy import ndimage

    if not section.any():
        return 0.0
    depth = ndimage.distance_transform_edt(np.pad(section, 1))[1:-1, 1:-1]
    ij = np.argwhere(depth >= depth.max() - 1.5 * voxel)
    ij = ij[:: max(1, len(ij) // CANDIDATES)]
    return float(dist.sample(coords[:, ij[:, 0], ij[:, 1]]).max())


def _measure_one(volume, fields: _Fields, point, normal, binormal, radius: float):
    """One section's numbers: ``(area, min, max, min_dir, max_dir, inscribed, threshold, centroid)``."""
    voxel = float(min(volume.spacing))
    pixel = PIXEL * voxel
    half = max(HALF_WIDTH * radius, radius + 4.0 * voxel)
    while True:
        coords = _plane(volume, point, normal, binormal, half, pixel)
        inside = fields.lumen_at(coords) >= 0.5
        section = _component(inside)
        threshold = np.nan
        if fields.values is not None and section.any():
            values = fields.values_at(coords)
            for _ in range(REFINE_STEPS):
                before = section
                section, threshold = _refined(section, inside & ~section, values, fields.sign, voxel, pixel)
                if np.array_equal(section, before):
                    break
        rim = np.concatenate([section[0], section[-1], section[:, 0], section[:, -1]])
        if not rim.any():
            break
        half *= 1.6
        if half > MAX_HALF_RADII * radius + 4.0 * voxel:
            break
    area = float(section.sum()) * pixel * pixel
    dmin, dmax, vmin, vmax = _feret(section, pixel, voxel, normal, binormal)
    inscribed = _inscribed(fields.distance, coords, section, voxel / pixel)
    uv = np.argwhere(section).mean(axis=0) * pixel - (section.shape[0] // 2) * pixel if section.any() else np.zeros(2)
    centroid = point + uv[0] * normal + uv[1] * binormal
    return area, dmin, dmax, vmin, vmax, inscribed, threshold, centroid


def _fields(volume, mask: np.ndarray, refine: bool) -> _Fields:
    """The fields the sections sample (the smoothed mask on the mask's box only: a whole CT in float32 would
    be hundreds of megabytes); the lumen's sign from its values against those of a shell two voxels round it."""
    from scipy import ndimage

    from ._inscribed import WallDistance

    h = np.asarray(volume.spacing, float)
    zyx = np.argwhere(mask)
    lo = np.maximum(zyx.min(axis=0) - 3, 0) if zyx.size else np.zeros(3, int)
    hi = np.minimum(zyx.max(axis=0) + 4, mask.shape) if zyx.size else np.array(mask.shape)
    box = tuple(slice(a, b) for a, b in zip(lo, hi, strict=True))
    sub = mask[box]
    smooth = ndimage.gaussian_filter(sub.astype(np.float32), MASK_SMOOTH * h.min() / h)
    values, sign, at = None, 1.0, np.zeros(3)
    if refine and zyx.size:
        values = np.asarray(volume.data)
        data = np.asarray(values[box])
        shell = ndimage.binary_dilation(sub, iterations=2) & ~sub
        sign = 1.0 if np.median(data[sub]) > np.median(data[shell]) else -1.0
        if sign < 0:
            at = np.maximum(lo - CUBIC_PAD, 0)
            wide = tuple(slice(a, b) for a, b in zip(at, np.minimum(hi + CUBIC_PAD, mask.shape), strict=True))
            values = ndimage.spline_filter(np.asarray(values[wide], np.float32), order=3, output=np.float32)
    return _Fields(smooth, lo.astype(float), WallDistance(mask, volume.spacing), values, sign, at.astype(float))


def measure_sections(volume, lumen: np.ndarray, centerline, *, refine: bool = False) -> Sections:
    """The cross-sections of ``lumen`` (bool ``[z, y, x]`` on ``volume``'s grid) at every point of
    ``centerline`` (world mm). ``refine``: draw each section's wall at its own half-way value of the data
    (a lumen grown from the data), else from the mask (a segmentation)."""
    _, normals, binormals = centerline.frames()
    fields = _fields(volume, np.asarray(lumen, bool), refine)
    voxel = float(min(volume.spacing))
    rows = [_measure_one(volume, fields, p, n, b, max(float(r), voxel))
            for p, n, b, r in zip(centerline.points, normals, binormals, centerline.radius, strict=True)]
    area, dmin, dmax, vmin, vmax, inscribed, threshold, centroid = (np.array(c) for c in zip(*rows, strict=True))
    sign = fields.sign
    return Sections(area, 2.0 * np.sqrt(area / np.pi), dmin, dmax, vmin, vmax, inscribed, threshold, centroid, sign)
