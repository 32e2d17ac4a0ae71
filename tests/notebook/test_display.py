"""Pictures that display themselves (volumen.notebook.pictures) and the linked slice views."""

from __future__ import annotations

import io

import numpy as np
import pytest
from PIL import Image as PILImage

from volumen.core import Image, Window, canonical, montage, slice_at, window_to_uint8
from volumen.data import phantom
from volumen.notebook.pictures import MESH_COLOR, mesh_picture


def _decode(png: bytes) -> np.ndarray:
    return np.asarray(PILImage.open(io.BytesIO(png)))


def test_image_png_is_its_8bit_picture():
    rng = np.random.default_rng(1)
    rgba = rng.random((12, 17, 4)).astype(np.float32)
    rgba[..., :3] *= rgba[..., 3:]
    img = Image(rgba=rgba, depth=np.zeros((12, 17), np.float32))
    assert np.array_equal(_decode(img._repr_png_()), img.to_uint8())


def test_volume_shows_its_montage_and_geometry(head32):
    assert np.array_equal(_decode(head32._repr_png_()), montage(head32))
    page = head32._repr_html_()
    assert "x".join(str(n) for n in head32.shape).replace("x", " x ") in page
    assert "RAS" in page and "data:image/png;base64," in page


def test_mesh_thumbnail_of_a_sphere_is_a_lambert_disc():
    """A sphere's silhouette fills pi r^2 of the picture (r = 0.45 * size: the bounding sphere fills 90 %)
    within 2 %; the shade is 0.2 + 0.8 |n . f|: about 1 at the centre (within 0.02 over the central 10 x 10
    pixels) and, averaged over the disc, 0.2 + 0.8 * 2/3 (the mean of sqrt(1 - rho^2) over a disc) within 0.01."""
    from volumen.surface import marching_cubes

    vol = phantom("sphere", 40, radius=15.0, antialias=True)
    mesh = marching_cubes(vol, 0.0)
    size = 200
    pic = mesh_picture(mesh.vertices, mesh.faces, size)
    disc = pic.max(axis=2) > 0
    assert disc.sum() == pytest.approx(np.pi * (0.45 * size) ** 2, rel=0.02)
    shade = pic[..., 0] / (255 * MESH_COLOR[0])
    assert shade[95:105, 95:105].mean() == pytest.approx(1.0, abs=0.02)
    assert shade[disc].mean() == pytest.approx(0.2 + 0.8 * 2 / 3, abs=0.01)
    assert np.array_equal(_decode(mesh._repr_png_()), mesh_picture(mesh.vertices, mesh.faces))


def test_slice_views_are_linked_and_windowed(head32):
    from volumen.notebook._slices import PLANE_COLOURS, SliceViews

    views = SliceViews(head32)
    can = canonical(head32)
    ni, nj, nk = can.shape[::-1]
    views.sliders["axial"].value = 5
    cor = views.picture("coronal")
    assert tuple(cor[nk - 1 - 5, 0]) == PLANE_COLOURS["axial"]  # the axial plane's line moved in the coronal view
    assert tuple(views.picture("sagittal")[nk - 1 - 5, 0]) == PLANE_COLOURS["axial"]
    views.level.value, views.width.value = 100.0, 1000.0
    ax = views.picture("axial")
    values, _ = slice_at(can, "axial", index=5, canonical_volume=can)
    expected = window_to_uint8(values, Window(level=100.0, width=1000.0))
    off_lines = np.ones(expected.shape, bool)
    off_lines[nj - 1 - nj // 2, :] = False
    off_lines[:, ni - 1 - ni // 2] = False
    assert np.array_equal(ax[..., 0][off_lines], expected[off_lines])
    assert _decode(views.images["axial"].value).shape[:2] == expected.shape
