"""Session fixtures of the surface tests (helpers in surface_fields.py)."""

from __future__ import annotations

import pytest

from tests.surface.surface_fields import ellipsoid_field
from volumen.core import Volume


@pytest.fixture(scope="session")
def sphere_volume() -> Volume:
    """Radius 20 mm sphere field on a 48^3 grid of 1 mm voxels."""
    return ellipsoid_field((48, 48, 48), (20.0, 20.0, 20.0))


@pytest.fixture(scope="session")
def sphere_mesh(sphere_volume):
    from volumen.surface import marching_cubes

    return marching_cubes(sphere_volume, 0.0)
