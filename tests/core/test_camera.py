"""Camera: anatomical views, orbit, projection conventions, JSON."""

from __future__ import annotations

import numpy as np
import pytest

from volumen.core import VIEWS, Camera, Volume, default_view

EXPECTED = {  # view -> (unit vector centre -> eye, up, image right)  in RAS+
    "anterior": ((0, 1, 0), (0, 0, 1), (-1, 0, 0)),   # facing the patient: their left on the image right
    "posterior": ((0, -1, 0), (0, 0, 1), (1, 0, 0)),
    "left": ((-1, 0, 0), (0, 0, 1), (0, -1, 0)),      # from the patient's left: face on the image left
    "right": ((1, 0, 0), (0, 0, 1), (0, 1, 0)),
    "superior": ((0, 0, 1), (0, 1, 0), (1, 0, 0)),
    "inferior": ((0, 0, -1), (0, 1, 0), (-1, 0, 0)),  # from the feet: patient's right on the image left
}


@pytest.fixture(scope="module")
def vol():
    aff = np.array([[0.8, 0, 0, -20.0], [0, 0.9, 0, 5.0], [0, 0, 1.2, 30.0], [0, 0, 0, 1]])
    return Volume(np.zeros((20, 30, 40), np.int16), spacing=(1.2, 0.9, 0.8), affine=aff)


@pytest.mark.parametrize("view", VIEWS)
@pytest.mark.parametrize("projection", ["perspective", "orthographic"])
def test_anatomical_views(vol, view, projection):
    cam = Camera.anatomical(vol, view, projection=projection)
    back, up, right = (np.array(v, float) for v in EXPECTED[view])
    np.testing.assert_allclose(cam.target, vol.center, atol=1e-9)
    eye_dir = np.subtract(cam.position, cam.target)
    np.testing.assert_allclose(eye_dir / np.linalg.norm(eye_dir), back, atol=1e-9)
    r, u, f = cam.basis()
    np.testing.assert_allclose(u, up, atol=1e-9)
    np.testing.assert_allclose(r, right, atol=1e-9)
    # the whole bounding sphere is in view: every corner projects inside the picture
    colrow, depth = cam.project(vol.corners(), (100, 100))
    assert np.all(colrow >= 0) and np.all(colrow <= 100) and np.all(depth > 0)


def test_anterior_projection_right_on_left_superior_on_top(vol):
    cam = Camera.anatomical(vol, "anterior")
    c = vol.center
    (col_r, row_r), _ = cam.project(c + [10, 0, 0], (64, 64))  # toward the patient's right
    (col_s, row_s), _ = cam.project(c + [0, 0, 10], (64, 64))  # toward superior
    assert col_r < 32 and abs(row_r - 32) < 1e-9
    assert row_s < 32 and abs(col_s - 32) < 1e-9


def test_orbit_rotates_as_documented(vol):
    ant = Camera.orbit(vol, view="anterior")
    d = ant.distance
    c = np.asarray(vol.center)
    # azimuth +90 from anterior: eye on the patient's left; -90: on the right
    np.testing.assert_allclose(Camera.orbit(vol, azimuth=90).position, c + [-d, 0, 0], atol=1e-9)
    np.testing.assert_allclose(Camera.orbit(vol, azimuth=-90).position, c + [d, 0, 0], atol=1e-9)
    np.testing.assert_allclose(Camera.orbit(vol, azimuth=90).position, Camera.anatomical(vol, "left").position,
                               atol=1e-9)
    # elevation +90: looking down from superior, up turned to posterior
    top = Camera.orbit(vol, elevation=90)
    np.testing.assert_allclose(top.position, c + [0, 0, d], atol=1e-9)
    np.testing.assert_allclose(top.basis()[1], [0, -1, 0], atol=1e-9)
    # 30 degrees: the eye stays at distance d, the angle from the start is 30 degrees
    cam = Camera.orbit(vol, azimuth=30)
    e = (np.asarray(cam.position) - c) / d
    assert abs(np.degrees(np.arccos(e @ [0, 1, 0])) - 30) < 1e-9 and e[0] < 0
    # zoom moves the eye closer (perspective) or shrinks the parallel scale
    assert Camera.orbit(vol, zoom=2).distance == pytest.approx(d / 2)
    o1, o2 = Camera.orbit(vol, projection="orthographic"), Camera.orbit(vol, projection="orthographic", zoom=2)
    assert o2.parallel_scale == pytest.approx(o1.parallel_scale / 2)


def test_project_depth_conventions(vol):
    cam = Camera(position=(0, 100, 0), target=(0, 0, 0), up=(0, 0, 1), fov=60)
    (col, row), depth = cam.project([10, 0, 0], (200, 100))
    assert depth == pytest.approx(np.hypot(100, 10))  # along the ray from the eye
    assert col < 100  # +x (patient's right) on the image left for a camera at +y
    ortho = cam.with_(projection="orthographic", parallel_scale=50)
    (col, row), depth = ortho.project([10, 0, 20], (200, 100))
    assert depth == pytest.approx(100) and col == pytest.approx(100 - 10 * 50 / 50) and row == pytest.approx(30)


def test_validation_and_json():
    cam = Camera(position=(1, 2, 3), target=(0, 0, 0), up=(0, 0, 1), fov=45, projection="orthographic",
                 parallel_scale=12.5, near=1.0, far=500.0)
    assert Camera.from_json(cam.to_json()) == cam
    with pytest.raises(ValueError, match="perspective"):
        Camera(position=(0, 1, 0), projection="fisheye")
    with pytest.raises(ValueError, match="parallel"):
        Camera(position=(0, 0, 5), up=(0, 0, 1))
    with pytest.raises(ValueError, match="fov"):
        Camera(position=(0, 1, 0), fov=0)
    with pytest.raises(ValueError, match="anterior"):
        Camera.anatomical(Volume(np.zeros((2, 2, 2))), "front")
    with pytest.raises(ValueError, match="unknown"):
        Camera.from_dict({"position": [0, 1, 0], "zoom": 2})


@pytest.mark.parametrize(("shape", "spacing", "view"), [
    ((20, 30, 40), (5.0, 0.7, 0.7), "anterior"), ((1, 30, 40), (5.0, 0.7, 0.7), "inferior"),
    ((20, 1, 40), (5.0, 0.7, 0.7), "anterior"), ((20, 30, 1), (5.0, 0.7, 0.7), "left"),
    ((1, 1, 1), (5.0, 0.7, 0.7), "anterior"), ((2, 100, 100), (1.0, 1.0, 1.0), "inferior"),
    ((34, 393, 157), (1.5, 0.88, 0.88), "anterior"), ((10, 512, 512), (5.0, 0.7, 0.7), "inferior"),
    ((60, 512, 512), (5.0, 0.7, 0.7), "anterior"), ((64, 256, 256), (1.0, 1.0, 1.0), "anterior")])
def test_default_view_faces_a_slab(shape, spacing, view):
    """Anterior, unless the volume is a slab (a single slice, two frames, ten 5 mm slices of a 36 cm field: along
    one axis less than a quarter as thick as along the next thinnest): then the view that faces it as radiology
    shows it (axial from the feet, coronal from the front, sagittal from the left), not one that sees it edge-on.
    VMTK's aorta (51 x 345 x 138 mm), a 60-slice CT and 64 mm of a 256 mm field (a quarter) are no slabs."""
    vol = Volume(np.zeros(shape, np.int16), spacing=spacing)
    assert default_view(vol) == view
    assert Camera.orbit(vol) == Camera.anatomical(vol) == Camera.orbit(vol, view=view)


def test_default_view_follows_the_slice_normal_in_the_world():
    """A slice stored with its k axis along anterior-posterior (a coronal image in an oblique-free affine) is
    seen from the front: the choice follows the affine, not the array axis."""
    affine = np.array([[0.7, 0, 0, 0], [0, 0, -5.0, 0], [0, 0.7, 0, 0], [0, 0, 0, 1.0]])  # i->x, j->z, k->-y
    assert default_view(Volume(np.zeros((1, 30, 40), np.int16), affine=affine)) == "anterior"
