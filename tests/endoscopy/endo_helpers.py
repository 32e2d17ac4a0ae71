"""Helpers of the endoscopy tests: exact distances to polylines and to the analytic torus."""

from __future__ import annotations

import numpy as np


def polyline_distance(points: np.ndarray, poly: np.ndarray) -> np.ndarray:
    """Distance (mm) from each point (n, 3) to the polyline ``poly`` (m, 3): exact point-segment distances."""
    a, b = poly[:-1], poly[1:]
    ab = b - a
    out = np.empty(len(points))
    for n, p in enumerate(points):
        t = np.clip(np.einsum("ij,ij->i", p - a, ab) / np.einsum("ij,ij->i", ab, ab), 0, 1)
        out[n] = np.min(np.linalg.norm(a + t[:, None] * ab - p, axis=1))
    return out


# An analytic curved tube: a torus, centre circle of radius TORUS_RC in the plane z = 0 around the
# origin, lumen radius TORUS_R. Its data is 100 HU per mm of signed distance to the surface, so the
# trilinear isosurface at 0 HU lies within ~0.01 mm of the exact torus at 1 mm voxels.
TORUS_RC, TORUS_R, TORUS_H = 40.0, 12.0, 1.0


def torus_wall_distance(p) -> np.ndarray:
    """Exact distance (mm) from points (n, 3) inside the torus to its wall."""
    p = np.atleast_2d(p)
    return TORUS_R - np.hypot(np.hypot(p[:, 0], p[:, 1]) - TORUS_RC, p[:, 2])
