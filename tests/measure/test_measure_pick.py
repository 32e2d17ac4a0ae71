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


def test_cpu_and_gl_pick_the_same_point():
    """The head phantom's CT look seen by its default camera: OpenGL's picks are the CPU's within a voxel (the
    page picks through the CPU on the server: tests/web/test_page_measure.py)."""
    from volumen.core import default_camera
    from volumen.data import phantom
    from volumen.render import default_look
    from volumen.render.raster import RasterUnavailable, get_context, on_gl_thread

    try:
        on_gl_thread(get_context)  # OpenGL objects live on the library's one OpenGL thread
    except RasterUnavailable as exc:  # as the raster tests do (tests/render/raster/conftest.py)
        print(f"gl pick not compared: {exc}")
        pytest.skip(str(exc))
    vol = phantom("head", size=64)
    mode, tf, _ = default_look(vol)
    scene, cam = Scene(volume=vol, transfer=tf, mode=mode), default_camera(vol)
    picked = 0
    for x, y in [(62.5, 70.5), (101.5, 84.5), (80.5, 80.5), (70.5, 40.5), (95.5, 120.5)]:
        cpu = pick(scene, cam, (160, 160), x, y, device="cpu")
        gl = pick(scene, cam, (160, 160), x, y, device="gl")
        assert (cpu is None) == (gl is None), (x, y)
        if cpu is not None:
            picked += 1
            assert np.linalg.norm(cpu - gl) < max(vol.spacing), (x, y)
    assert picked >= 4
