"""Rays: primary rays from a packed camera, and their exact interval inside the drawn region.

The camera and the volume geometry are packed into small float64 arrays
(Python side: :func:`pack_camera`, :func:`pack_geometry`) so the kernels see
arrays and scalars only. A ray is ``p(t) = o + t d`` in world mm with ``d``
a unit vector, so ``t`` is the depth written into ``Image.depth``. The
same ray in voxel-index space is ``o' + t d'`` with ``o' = A^-1 o`` and
``d' = A^-1 d`` (``A`` the affine), which is how oblique volumes work.

Drawn region = volume box of voxel centres (index space ``[0, n-1]``)
  ∩ crop box (index space, or world axis-aligned)
  ∩ each clip plane's kept half-space ``dot(x - p, n) >= 0``
  ∩ ``[near, far]`` along the ray.
"""

from __future__ import annotations

import math

import numpy as np

from ...jit import njit

__all__ = ["pack_camera", "pack_geometry", "pack_planes", "primary_ray", "pixel_ray", "ray_interval", "region_interval",
           "footprint", "C_ORTHO", "G_BOX", "G_INV", "P_POINT", "P_NORMAL"]

# packed camera layout
C_EYE, C_RIGHT, C_UP, C_FWD, C_ORTHO, C_HALF, C_W, C_H, C_NEAR, C_FAR = 0, 3, 6, 9, 12, 13, 14, 15, 16, 17
# packed geometry layout: world->index 3x4, then index box lo/hi (with crop), then world crop lo/hi
G_INV, G_BOX, G_WORLD = 0, 12, 18
# packed clip plane layout (a row of ``pack_planes``): a point on the plane, its unit normal
P_POINT, P_NORMAL = 0, 3
_FAR = 1e30  # finite stand-in for infinity (the kernels use fastmath)


def pack_camera(camera, size) -> np.ndarray:
    """float64 (18,): eye, right, up, forward, ortho flag, half height (tan(fov/2) or parallel scale), W, H, near,
    far."""
    w, h = size
    r, u, f = camera.basis()
    ortho = camera.projection == "orthographic"
    half = camera.parallel_scale if ortho else np.tan(np.radians(camera.fov) / 2)
    near = 0.0 if camera.near is None else camera.near
    far = _FAR if camera.far is None else camera.far
    return np.array([*camera.position, *r, *u, *f, float(ortho), half, w, h, near, far], np.float64)


def pack_geometry(volume, clipping) -> np.ndarray:
    """float64 (24,): world->index affine rows (3x4), index box lo/hi (xyz, crop applied), world crop lo/hi."""
    inv = np.linalg.inv(np.asarray(volume.affine, float))[:3, :4]
    nz, ny, nx = volume.shape
    lo = np.zeros(3)
    hi = np.array([nx - 1, ny - 1, nz - 1], float)
    wlo = np.full(3, -_FAR)
    whi = np.full(3, _FAR)
    if clipping.crop is not None:
        c = np.asarray(clipping.crop, float)
        if clipping.crop_space == "voxel":
            lo, hi = np.maximum(lo, c[0::2]), np.minimum(hi, c[1::2])
        else:
            wlo, whi = c[0::2], c[1::2]
    return np.concatenate([inv.ravel(), lo, hi, wlo, whi]).astype(np.float64)


def pack_planes(clipping) -> np.ndarray:
    """float64 (n, 6): point, unit normal of each clip plane ((1, 6) of zeros-normal when none)."""
    if not clipping.planes:
        return np.zeros((1, 6), np.float64)
    return np.array([[*p.point, *(np.asarray(p.normal) / np.linalg.norm(p.normal))] for p in clipping.planes],
                    np.float64)


def footprint(cam: np.ndarray, geo: np.ndarray) -> tuple[int, int, int, int]:
    """Pixel bounds ``(x0, y0, x1, y1)`` (x1, y1 exclusive) outside which no view ray meets the index box.

    The box's eight corners projected by the packed camera bound its picture
    (a convex box projects into the hull of its corners' images); one pixel
    of margin covers rounding. The whole picture when a corner is not in
    front of the eye (perspective), where that bound does not hold; nothing
    when every corner is behind it.
    """
    w, h = int(cam[C_W]), int(cam[C_H])
    inv = np.vstack([geo[G_INV:G_INV + 12].reshape(3, 4), [0.0, 0.0, 0.0, 1.0]])
    lo, hi = geo[G_BOX:G_BOX + 3], geo[G_BOX + 3:G_BOX + 6]
    idx = np.array([[x, y, z, 1.0] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    v = (np.linalg.inv(inv) @ idx.T)[:3].T - cam[C_EYE:C_EYE + 3]
    sx, sy, sz = v @ cam[C_RIGHT:C_RIGHT + 3], v @ cam[C_UP:C_UP + 3], v @ cam[C_FWD:C_FWD + 3]
    if cam[C_ORTHO] <= 0.5:
        eps = 1e-9 * (1.0 + np.abs(v).max())
        if np.all(sz <= -eps) and cam[C_NEAR] >= 0.0:
            return 0, 0, 0, 0
        if not np.all(sz > eps):
            return 0, 0, w, h
        sx, sy = sx / sz, sy / sz
    px = sx / cam[C_HALF] * (0.5 * h) + 0.5 * w - 0.5
    py = 0.5 * h - 0.5 - sy / cam[C_HALF] * (0.5 * h)
    x0, x1 = max(int(np.floor(px.min())) - 1, 0), min(int(np.ceil(px.max())) + 2, w)
    y0, y1 = max(int(np.floor(py.min())) - 1, 0), min(int(np.ceil(py.max())) + 2, h)
    if x1 <= x0 or y1 <= y0:
        return 0, 0, 0, 0
    return x0, y0, x1, y1

@njit(cache=True, fastmath=True, inline="always")
def primary_ray(cam, px, py):
    """World ray through the centre of pixel (px, py): ``(ox, oy, oz, dx, dy, dz)``, d unit."""
    return pixel_ray(cam, px + 0.5, py + 0.5)


@njit(cache=True, fastmath=True, inline="always")
def pixel_ray(cam, x, y):
    """World ray through the picture point ``(x, y)`` (pixels from the top left corner: pixel (px, py) spans
    ``[px, px + 1) x [py, py + 1)``): ``(ox, oy, oz, dx, dy, dz)``, d unit."""
    w = cam[C_W]
    h = cam[C_H]
    sx = (x - 0.5 * w) / (0.5 * h) * cam[C_HALF]
    sy = (0.5 * h - y) / (0.5 * h) * cam[C_HALF]
    if cam[C_ORTHO] > 0.5:
        ox = cam[C_EYE] + sx * cam[C_RIGHT] + sy * cam[C_UP]
        oy = cam[C_EYE + 1] + sx * cam[C_RIGHT + 1] + sy * cam[C_UP + 1]
        oz = cam[C_EYE + 2] + sx * cam[C_RIGHT + 2] + sy * cam[C_UP + 2]
        return ox, oy, oz, cam[C_FWD], cam[C_FWD + 1], cam[C_FWD + 2]
    dx = cam[C_FWD] + sx * cam[C_RIGHT] + sy * cam[C_UP]
    dy = cam[C_FWD + 1] + sx * cam[C_RIGHT + 1] + sy * cam[C_UP + 1]
    dz = cam[C_FWD + 2] + sx * cam[C_RIGHT + 2] + sy * cam[C_UP + 2]
    n = 1.0 / math.sqrt(dx * dx + dy * dy + dz * dz)
    return cam[C_EYE], cam[C_EYE + 1], cam[C_EYE + 2], dx * n, dy * n, dz * n


@njit(cache=True, fastmath=False)
def _slab(o, d, lo, hi, t0, t1):
    """Intersect [t0, t1] with {t : lo <= o + t d <= hi} on one axis."""
    if d == 0.0:
        if o < lo or o > hi:
            return 1.0, 0.0
        return t0, t1
    a = (lo - o) / d
    b = (hi - o) / d
    if a > b:
        a, b = b, a
    return max(t0, a), min(t1, b)


@njit(cache=True, fastmath=False, inline="always")
def to_index(geo, x, y, z, w):
    """World point (w = 1) or direction (w = 0) -> voxel index space."""
    i = geo[G_INV] * x + geo[G_INV + 1] * y + geo[G_INV + 2] * z + geo[G_INV + 3] * w
    j = geo[G_INV + 4] * x + geo[G_INV + 5] * y + geo[G_INV + 6] * z + geo[G_INV + 7] * w
    k = geo[G_INV + 8] * x + geo[G_INV + 9] * y + geo[G_INV + 10] * z + geo[G_INV + 11] * w
    return i, j, k


@njit(cache=True, fastmath=False, inline="always")
def _side(planes, p, x, y, z):
    """Signed distance (mm) of world point (x, y, z) from clip plane ``p``: the kept side is positive."""
    return ((x - planes[p, P_POINT]) * planes[p, P_NORMAL] + (y - planes[p, P_POINT + 1]) * planes[p, P_NORMAL + 1]
            + (z - planes[p, P_POINT + 2]) * planes[p, P_NORMAL + 2])


@njit(cache=True, fastmath=False, inline="always")
def region_interval(geo, planes, nplanes, o, d, t0, t1):
    """``[t0, t1]`` intersected with the drawn region (volume box, crop, clip planes) along ``o + t d``
    (world mm, ``o`` and ``d`` (x, y, z) tuples; ``d`` of any length); empty when the result has t1 < t0."""
    ox, oy, oz = o
    dx, dy, dz = d
    oi, oj, ok = to_index(geo, ox, oy, oz, 1.0)
    di, dj, dk = to_index(geo, dx, dy, dz, 0.0)
    t0, t1 = _slab(oi, di, geo[G_BOX], geo[G_BOX + 3], t0, t1)
    t0, t1 = _slab(oj, dj, geo[G_BOX + 1], geo[G_BOX + 4], t0, t1)
    t0, t1 = _slab(ok, dk, geo[G_BOX + 2], geo[G_BOX + 5], t0, t1)
    t0, t1 = _slab(ox, dx, geo[G_WORLD], geo[G_WORLD + 3], t0, t1)
    t0, t1 = _slab(oy, dy, geo[G_WORLD + 1], geo[G_WORLD + 4], t0, t1)
    t0, t1 = _slab(oz, dz, geo[G_WORLD + 2], geo[G_WORLD + 5], t0, t1)
    for p in range(nplanes):
        s = _side(planes, p, ox, oy, oz)
        dn = dx * planes[p, P_NORMAL] + dy * planes[p, P_NORMAL + 1] + dz * planes[p, P_NORMAL + 2]
        if dn == 0.0:
            if s < 0.0:
                return 1.0, 0.0
        elif dn > 0.0:
            t0 = max(t0, -s / dn)
        else:
            t1 = min(t1, -s / dn)
    return t0, t1


@njit(cache=True, fastmath=False, inline="always")
def _inside(geo, planes, nplanes, x, y, z):
    """Whether world point (x, y, z) lies in the drawn region (volume box, crop, clip planes; boundaries in)."""
    i, j, k = to_index(geo, x, y, z, 1.0)
    if not (geo[G_BOX] <= i <= geo[G_BOX + 3] and geo[G_BOX + 1] <= j <= geo[G_BOX + 4]
            and geo[G_BOX + 2] <= k <= geo[G_BOX + 5]):
        return False
    if not (geo[G_WORLD] <= x <= geo[G_WORLD + 3] and geo[G_WORLD + 1] <= y <= geo[G_WORLD + 4]
            and geo[G_WORLD + 2] <= z <= geo[G_WORLD + 5]):
        return False
    for p in range(nplanes):
        if _side(planes, p, x, y, z) < 0.0:
            return False
    return True


@njit(cache=True, fastmath=False, inline="always")
def segment_interval(geo, planes, nplanes, o, d, t1):
    """:func:`region_interval` of ``[0, t1]``; without its divisions where both ends lie in the region (which is
    convex, so the whole segment does: ``(0, t1)``)."""
    ox, oy, oz = o
    dx, dy, dz = d
    if _inside(geo, planes, nplanes, ox, oy, oz) and _inside(geo, planes, nplanes, ox + t1 * dx, oy + t1 * dy,
                                                             oz + t1 * dz):
        return 0.0, t1
    return region_interval(geo, planes, nplanes, o, d, 0.0, t1)


@njit(cache=True, fastmath=False, inline="always")
def ray_interval(cam, geo, planes, nplanes, o, d):
    """``(t0, t1)`` of the view ray ``o + t d`` inside the drawn region and the camera's [near, far] (empty when
    t1 < t0)."""
    return region_interval(geo, planes, nplanes, o, d, cam[C_NEAR], cam[C_FAR])
