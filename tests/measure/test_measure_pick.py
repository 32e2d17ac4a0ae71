"""3-D picking: the first visible surface along a clicked pixel's ray, on a ball's surface within a voxel
(perspective and orthographic), on that ray, and nearest the eye."""

import numpy as np
import pytest

from volumen.core import Camera, Scene, TransferFunction, Volume
from volumen.measure._pick import pick, pixel_ray

SPACING = 1.5
RADIUS = 25.0


@pytest.fixture(scope="module")
def sphere():
    """A CT of a bone-dense ball (1000 HU, radius 25 mm) in air, 1.5 mm voxels, drawn opaque from 0 HU: its
    visible surface is where the interpolated values cross 0 HU, the ball's own."""
    n = 56
    zyx = (np.indices((n, n, n)).transpose(1, 2, 3, 0) - (n - 1) / 2) * SPACING
    data = np.where((zyx**2).sum(-1) <= RADIUS**2, 1000, -1000).astype(np.int16)
    vol = Volume(data, spacing=(SPACING,) * 3, modality="CT", units="HU")
    tf = TransferFunction(color=[(-1000, 1, 1, 1), (1000, 1, 1, 1)], opacity=[(-1000, 0), (-1, 0), (0, 1), (1000, 1)])
    return vol, Scene(volume=vol, transfer=tf, mode="composite")


def _near_side(origin, direction, centre) -> float:
    """Distance along a ray to the midpoint of its chord through the ball: the near half lies before it."""
    return float((centre - origin) @ direction)


@pytest.mark.parametrize("projection", ["perspective", "orthographic"])
def test_a_click_picks_the_first_surface_along_its_ray(sphere, projection):
    vol, scene = sphere
    centre = np.asarray(vol.center)
    cam = Camera(position=tuple(centre + (40.0, -220.0, 30.0)), target=tuple(centre), up=(0, 0, 1), fov=30.0,
                 projection=projection, parallel_scale=60.0)
    size = (160, 120)
    for x, y in [(80.0, 60.0), (92.5, 49.2), (68.3, 71.9)]:
        got = pick(scene, cam, size, x, y)
        origin, direction = pixel_ray(cam, size, x, y)
        along = (got - origin) @ direction
        assert abs(np.linalg.norm(got - centre) - RADIUS) < SPACING, (x, y)  # on the surface
        assert np.linalg.norm(got - origin - along * direction) < 1e-6  # on the clicked ray
        assert along < _near_side(origin, direction, centre)  # its near side
    assert pick(scene, cam, size, 2.0, 2.0) is None  # past the ball: nothing visible


def test_pixel_ray_is_camera_project_backwards():
    cam = Camera(position=(10.0, -300.0, 20.0), target=(0.0, 0.0, 0.0), up=(0, 0, 1), fov=40.0)
    origin, direction = pixel_ray(cam, (200, 100), 37.0, 81.0)
    colrow, depth = cam.project(origin + 123.0 * direction, (200, 100))
    assert np.allclose(colrow, (37.0, 81.0)) and depth == pytest.approx(123.0)
