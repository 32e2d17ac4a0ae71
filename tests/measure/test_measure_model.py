"""The measurement model against analytic answers: distances and angles between blobs found on an anisotropic,
oblique grid, region statistics against numpy over the same voxels chosen by a second method, a sphere's volume."""

import numpy as np
import pytest
from matplotlib.path import Path as MplPath

from volumen import measure
from volumen.core import LabelMap, Volume
from volumen.errors import OutsideVolumeError


def _oblique_affine(spacing_xyz=(0.7, 0.9, 1.6), degrees=23.0, origin=(-40.0, -35.0, -30.0)):
    """Voxel (i, j, k) -> world: axes rotated about z and x, anisotropic spacing."""
    a, b = np.radians(degrees), np.radians(degrees / 2)
    rz = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    rx = np.array([[1, 0, 0], [0, np.cos(b), -np.sin(b)], [0, np.sin(b), np.cos(b)]])
    affine = np.eye(4)
    affine[:3, :3] = rz @ rx @ np.diag(spacing_xyz)
    affine[:3, 3] = origin
    return affine


def _world_grid(affine, shape):
    k, j, i = np.meshgrid(*(np.arange(n) for n in shape), indexing="ij")
    ijk = np.stack([i, j, k], axis=-1).astype(float)
    return ijk @ affine[:3, :3].T + affine[:3, 3]


def _blobs(points, affine, shape=(48, 96, 110), sigma=2.0):
    """A volume with a Gaussian blob (sigma mm) at each world point."""
    xyz = _world_grid(affine, shape)
    data = sum(1000.0 * np.exp(-((xyz - p) ** 2).sum(-1) / (2 * sigma**2)) for p in points)
    return Volume(data.astype(np.float32), affine=affine)


def _centroid(volume, near, radius=6.0):
    """The intensity-weighted centre (world mm) of the blob within ``radius`` mm of ``near``: a click refined to
    the blob, independent of the measurement code."""
    xyz = _world_grid(volume.affine, volume.shape)
    w = np.where(((xyz - near) ** 2).sum(-1) < radius**2, volume.data, 0.0)
    return (xyz * w[..., None]).sum(axis=(0, 1, 2)) / w.sum()


POINTS = np.array([[-12.3, 4.1, -3.2], [17.6, -8.9, 5.4], [3.0, 19.5, -1.7]])


def test_distance_between_blobs_within_half_a_voxel():
    affine = _oblique_affine()
    vol = _blobs(POINTS[:2], affine)
    p, q = (_centroid(vol, x) for x in POINTS[:2])
    ruler = measure.distance(p, q, volume=vol)
    truth = float(np.linalg.norm(POINTS[1] - POINTS[0]))
    assert abs(ruler.mm - truth) < 0.5 * min(0.7, 0.9, 1.6)  # half the finest voxel
    assert ruler.row()["value"] == f"{ruler.mm:.1f}"


def test_angle_between_blobs_within_half_a_degree():
    affine = _oblique_affine()
    vol = _blobs(POINTS, affine)
    a, vertex, b = (_centroid(vol, x) for x in POINTS)
    u, v = POINTS[0] - POINTS[1], POINTS[2] - POINTS[1]
    truth = np.degrees(np.arccos(u @ v / np.linalg.norm(u) / np.linalg.norm(v)))
    assert abs(measure.angle(a, vertex, b).degrees - truth) < 0.5
    assert measure.angle((1, 0, 0), (0, 0, 0), (0, 0, 5)).degrees == pytest.approx(90.0, abs=1e-9)
    assert measure.angle((1, 0, 0), (0, 0, 0), (-2, 0, 0)).degrees == pytest.approx(180.0, abs=1e-9)


def _noise_volume(affine=None, shape=(20, 60, 70), spacing=(2.5, 0.8, 0.6)):
    rng = np.random.default_rng(7)
    data = (rng.normal(40.0, 25.0, shape) + np.arange(shape[2]) * 3.0).astype(np.float32)
    return Volume(data, spacing=None if affine is not None else spacing, affine=affine, units="HU", modality="CT")


def test_axial_ellipse_rectangle_polygon_match_numpy_over_the_same_voxels():
    vol = _noise_volume()
    k = 9
    plane = measure.slice_plane(vol, "axial", k)
    jj, ii = np.meshgrid(np.arange(vol.shape[1]), np.arange(vol.shape[2]), indexing="ij")
    x, y = ii * 0.6, jj * 0.8  # the plane's (s, t) are the voxel axes i, j from slice k's first voxel
    shapes = {
        "ellipse": (measure.Ellipse((20.3, 23.1), (11.2, 7.9)),
                    ((x - 20.3) / 11.2) ** 2 + ((y - 23.1) / 7.9) ** 2 <= 1),
        "rectangle": (measure.Rectangle((5.1, 4.3), (30.1, 20.3)), (x >= 5.1) & (x <= 30.1) & (y >= 4.3) & (y <= 20.3)),
        "polygon": (measure.Polygon(((3.3, 2.1), (35.2, 8.7), (14.9, 40.2))),
                    MplPath([(3.3, 2.1), (35.2, 8.7), (14.9, 40.2)]).contains_points(
                        np.c_[x.ravel(), y.ravel()]).reshape(x.shape)),
    }
    for name, (shape, mask) in shapes.items():
        values = vol.data[k][mask].astype(np.float64)
        r = measure.roi_stats(vol, plane, shape)
        assert r.voxels == values.size, name
        assert r.mean == pytest.approx(values.mean(), rel=0.005), name
        assert r.sd == pytest.approx(values.std(), rel=0.005), name
        assert (r.min, r.max, r.median) == pytest.approx((values.min(), values.max(), np.median(values))), name
        assert r.units == "HU"
    assert shapes["ellipse"][0].area == pytest.approx(np.pi * 11.2 * 7.9)
    assert measure.roi_stats(vol, plane, shapes["rectangle"][0]).area_mm2 == pytest.approx(25.0 * 16.0)


def _cut_by_plane(affine, shape, plane):
    """A second method: a voxel's box is cut by the plane where its eight corners do not all lie on one side."""
    xyz = _world_grid(affine, shape)
    signs = []
    for corner in np.array(np.meshgrid([-0.5, 0.5], [-0.5, 0.5], [-0.5, 0.5])).reshape(3, -1).T:
        offset = affine[:3, :3] @ corner
        signs.append(np.sign((xyz + offset - plane.origin) @ plane.normal))
    signs = np.array(signs)
    return xyz, (signs.max(axis=0) >= 0) & (signs.min(axis=0) <= 0)


def test_oblique_plane_on_an_anisotropic_oblique_grid_matches_numpy():
    affine = _oblique_affine()
    vol = _noise_volume(affine=affine, shape=(40, 70, 80))
    plane = measure.Plane.through(vol.center + (1.3, -2.1, 0.7), normal=(0.3, -0.5, 0.8))
    ellipse = measure.Ellipse((2.0, -3.0), (14.0, 9.0))
    xyz, cut = _cut_by_plane(affine, vol.shape, plane)
    d = xyz - plane.origin
    s, t = d @ np.asarray(plane.u), d @ np.asarray(plane.v)
    mask = cut & (((s - 2.0) / 14.0) ** 2 + ((t + 3.0) / 9.0) ** 2 <= 1)
    values = vol.data[mask].astype(np.float64)
    r = measure.roi_stats(vol, plane, ellipse)
    assert r.voxels == values.size > 300
    assert r.mean == pytest.approx(values.mean(), rel=0.005)
    assert r.sd == pytest.approx(values.std(), rel=0.005)


def test_region_outside_the_volume_is_one_line():
    vol = _noise_volume()
    plane = measure.slice_plane(vol, "axial", 3)
    with pytest.raises(OutsideVolumeError) as err:
        measure.roi_stats(vol, plane, measure.Ellipse((500.0, 500.0), (5.0, 5.0)))
    assert "\n" not in str(err.value) and "holds no voxel" in str(err.value)


def test_sphere_label_volume_within_one_percent():
    spacing = (0.9, 0.7, 0.8)
    shape = (60, 80, 70)
    zyx = np.stack(np.meshgrid(*(np.arange(n) * s for n, s in zip(shape, spacing, strict=True)), indexing="ij"), -1)
    r = 19.0
    inside = ((zyx - (27.0, 28.0, 27.5)) ** 2).sum(-1) <= r**2
    labels = LabelMap(inside.astype(np.uint8) * 3, spacing=spacing, names={3: "sphere"})
    (found,) = measure.label_volumes(labels)
    assert (found.value, found.label) == (3, "sphere")
    assert found.ml == pytest.approx(4 / 3 * np.pi * r**3 / 1000.0, rel=0.01)


def test_measurements_round_trip_and_show_as_a_table():
    vol = _noise_volume()
    plane = measure.slice_plane(vol, "coronal", 30)
    items = measure.Measurements([
        measure.distance((0, 0, 0), (3, 4, 0), volume=vol, label="a"),
        measure.angle((1, 0, 0), (0, 0, 0), (0, 1, 0)),
        measure.point((1, 2, 3)),
        measure.roi_stats(vol, plane, measure.Rectangle((2, 2), (9, 6))),
    ])
    again = measure.Measurements.from_dicts(items.to_dicts())
    assert again == items
    html = items._repr_html_()
    assert html.count("<tr>") == 5 and "5.0" in html and "90.0" in html
    assert items.to_csv().splitlines()[0].startswith("kind,label,value,unit,mean")
