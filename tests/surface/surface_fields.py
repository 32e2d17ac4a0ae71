"""Fields and mesh checks for the surface tests: smooth signed-distance-like functions sampled at voxel centres."""

from __future__ import annotations

import numpy as np

from volumen.core import Volume


def ellipsoid_field(shape, semi_axes_mm, spacing=(1.0, 1.0, 1.0), centre_mm=None) -> Volume:
    """Positive inside the ellipsoid ``(x/a)^2 + (y/b)^2 + (z/c)^2 = 1`` (semi-axes (a, b, c) mm along x, y, z).

    The value is ``(1 - q) * min(a, b, c)`` with q the ellipsoidal radius, close to a signed
    distance in mm near the surface; level 0 is the ellipsoid exactly.
    """
    nz, ny, nx = shape
    dz, dy, dx = spacing
    if centre_mm is None:
        centre_mm = ((nx - 1) * dx / 2 + 0.31, (ny - 1) * dy / 2 - 0.17, (nz - 1) * dz / 2 + 0.23)
    a, b, c = semi_axes_mm
    z = np.arange(nz)[:, None, None] * dz - centre_mm[2]
    y = np.arange(ny)[None, :, None] * dy - centre_mm[1]
    x = np.arange(nx)[None, None, :] * dx - centre_mm[0]
    q = np.sqrt((x / a) ** 2 + (y / b) ** 2 + (z / c) ** 2)
    data = ((1.0 - q) * min(a, b, c)).astype(np.float32)
    vol = Volume(data, spacing=spacing)
    vol.meta["centre_mm"] = np.array(centre_mm)
    return vol


def ellipsoid_area(a: float, b: float, c: float) -> float:
    """Exact surface area of an ellipsoid (Legendre's elliptic-integral formula)."""
    from scipy.special import ellipeinc, ellipkinc

    a, b, c = sorted((a, b, c), reverse=True)
    if np.isclose(a, c):
        return 4 * np.pi * a * a
    phi = np.arccos(c / a)
    m = (a * a * (b * b - c * c)) / (b * b * (a * a - c * c))
    s = np.sin(phi)
    return float(2 * np.pi * c * c
                 + 2 * np.pi * a * b / s * (ellipeinc(phi, m) * s * s + ellipkinc(phi, m) * np.cos(phi) ** 2))


def edge_counts(faces: np.ndarray) -> np.ndarray:
    """How many triangles share each undirected edge."""
    e = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    _, counts = np.unique(e, axis=0, return_counts=True)
    return counts


def directed_edges_unique(faces: np.ndarray) -> bool:
    """True when no directed edge repeats: neighbouring triangles wind consistently."""
    d = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]).astype(np.int64)
    key = d[:, 0] * (d.max() + 1) + d[:, 1]
    return len(np.unique(key)) == len(key)
