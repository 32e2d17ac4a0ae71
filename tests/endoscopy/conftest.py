"""Fixtures of the endoscopy tests: the torso phantom's colon, its computed lumen and centerline, an analytic torus."""

from __future__ import annotations

import numpy as np
import pytest

from volumen.core import Volume


@pytest.fixture(scope="session")
def torso():
    from volumen.data import phantom

    return phantom("torso")


@pytest.fixture(scope="session")
def colon_lumen(torso):
    from volumen.endoscopy import lumen_mask

    return lumen_mask(torso, torso.meta["truth"]["colon"].centerline[0])


@pytest.fixture(scope="session")
def colon_centerline(torso, colon_lumen):
    from volumen.endoscopy import compute_centerline

    return compute_centerline(torso, colon_lumen)


@pytest.fixture(scope="session")
def endo_dir(output_dir):
    d = output_dir / "endoscopy"
    d.mkdir(exist_ok=True)
    return d


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


@pytest.fixture(scope="session")
def torus() -> Volume:
    n = int((TORUS_RC + TORUS_R + 6) * 2 / TORUS_H) + 1
    nz = int((TORUS_R + 6) * 2 / TORUS_H) + 1
    z, y, x = np.meshgrid(np.arange(nz), np.arange(n), np.arange(n), indexing="ij")
    ox, oz = -(n - 1) / 2 * TORUS_H, -(nz - 1) / 2 * TORUS_H
    X, Y, Z = ox + x * TORUS_H, ox + y * TORUS_H, oz + z * TORUS_H
    d = np.hypot(np.hypot(X, Y) - TORUS_RC, Z)
    data = np.clip(100.0 * (d - TORUS_R), -1000, 1000).astype(np.float32)
    aff = np.diag([TORUS_H, TORUS_H, TORUS_H, 1.0])
    aff[:3, 3] = (ox, ox, oz)
    return Volume(data, spacing=(TORUS_H,) * 3, affine=aff, modality="CT", units="HU")
