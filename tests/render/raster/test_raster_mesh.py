"""OpenGL meshes: depth against the ray caster's isosurface, lights, the head phantom (skips without OpenGL)."""

from __future__ import annotations

import numpy as np
import pytest

from tests.render.raster.raster_helpers import save_row
from volumen.core import Camera, Isosurface, Light, Sampling, Scene, Shading
from volumen.render import render
from volumen.render.raster import MeshOptions, isosurface_mesh, render_isosurface_mesh, render_mesh

ISO = 300.0


def _iso_scene(volume, shading="headlight", lights=()):
    return Scene(volume=volume, mode="isosurface", isosurface=Isosurface(value=ISO), shading=Shading(mode=shading),
                 lights=lights, sampling=Sampling(jitter=False))


@pytest.mark.parametrize("projection", ["orthographic", "perspective"])
@pytest.mark.parametrize("shading", ["phong", "gouraud"])
def test_mesh_depth_agrees_with_isosurface_ray_casting(gl, blob, projection, shading):
    """Same threshold, two methods: depth maps within one voxel (1 mm) wherever both hit, silhouette pixels
    (next to a miss, where a grazing ray meets the trilinear surface and its linear mesh apart) within two;
    median difference < 0.05 mm; hit masks equal on > 98 % of pixels; headlight colours close (mean < 0.02)."""
    from scipy.ndimage import binary_erosion

    scene = _iso_scene(blob)
    cam = Camera.orbit(blob, azimuth=35, elevation=25, projection=projection, zoom=1.2)
    ref = render(scene, cam, (64, 64))
    img = render_isosurface_mesh(scene, cam, (64, 64), MeshOptions(shading=shading))
    a, b = np.isfinite(ref.depth), np.isfinite(img.depth)
    both = a & b
    assert both.sum() > 400 and np.mean(a == b) > 0.98
    err = np.abs(ref.depth[both] - img.depth[both])
    inner = binary_erosion(both, np.ones((3, 3)), border_value=0)
    assert np.abs(ref.depth[inner] - img.depth[inner]).max() < 1.0
    assert err.max() < 2.0 and np.median(err) < 0.05, (err.max(), np.median(err))
    assert np.abs(ref.rgba - img.rgba).mean() < 0.02


def test_skimage_mesh_gives_the_same_depth(gl, blob):
    """An independent mesh (scikit-image's marching cubes, put in world mm by the affine) draws the same depth."""
    skimage = pytest.importorskip("skimage.measure")
    from volumen.surface import Mesh

    verts, faces, _, _ = skimage.marching_cubes(blob.data, ISO)
    world = blob.index_to_world(verts[:, ::-1])  # (z, y, x) -> (i, j, k) -> world mm
    mesh = Mesh(world.astype(np.float32), faces.astype(np.int32))
    cam = Camera.orbit(blob, azimuth=-50, elevation=10, zoom=1.2)
    ours = render_isosurface_mesh(_iso_scene(blob), cam, (64, 64))
    theirs = render_mesh(mesh, cam, (64, 64), scene=_iso_scene(blob))
    both = np.isfinite(ours.depth) & np.isfinite(theirs.depth)
    assert both.sum() > 400
    assert np.abs(ours.depth[both] - theirs.depth[both]).max() < 0.5


def test_any_number_of_lights_adds_up(gl, blob):
    """Lighting is linear in the lights: seven lights of 1/7 intensity at one spot give the picture
    of one light; two different spot lights give the sum of their separate contributions."""
    c = blob.center
    cam = Camera.orbit(blob, azimuth=20, zoom=1.2)
    one = Light(position=tuple(c + [0, 80, 40]), direction=(0, -1, -0.5), intensity=1.0, exponent=4.0)
    seven = tuple(Light(position=one.position, direction=one.direction, intensity=1 / 7, exponent=4.0)
                  for _ in range(7))
    size = (48, 48)
    im1 = render_isosurface_mesh(_iso_scene(blob, "phong", (one,)), cam, size)
    im7 = render_isosurface_mesh(_iso_scene(blob, "phong", seven), cam, size)
    assert np.abs(im1.rgba - im7.rgba).max() < 1e-4
    other = Light(position=tuple(c + [80, 0, 0]), direction=(-1, 0, 0), intensity=0.6, color=(1, 0.5, 0.2))
    amb = _iso_scene(blob, "phong", ())
    i_a, i_b = (render_isosurface_mesh(_iso_scene(blob, "phong", (x,)), cam, size) for x in (one, other))
    i_ab = render_isosurface_mesh(_iso_scene(blob, "phong", (one, other)), cam, size)
    i_0 = render_isosurface_mesh(amb, cam, size)
    hit = np.isfinite(i_ab.depth) & (i_ab.rgba[..., :3].max(axis=-1) < 0.999)  # unclipped pixels
    lhs = i_ab.rgba[..., :3][hit]
    rhs = (i_a.rgba[..., :3] + i_b.rgba[..., :3] - i_0.rgba[..., :3])[hit]
    assert hit.sum() > 300 and np.abs(lhs - rhs).max() < 1e-4
    # the mesh and the ray caster light it the same way
    ref = render(_iso_scene(blob, "phong", (one, other)), cam, size)
    assert np.abs(ref.rgba - i_ab.rgba).mean() < 0.02


def test_head_phantom_mesh(gl, raster_dir):
    """The head phantom's bone surface at 300 HU, anterior view: upright (skull top in the upper half),
    the right-side bead on the image's LEFT (patient facing us); Phong and Gouraud side by side."""
    from volumen.data import phantom

    head = phantom("head")
    mesh = isosurface_mesh(head, ISO)
    assert mesh.n_faces > 10_000
    scene = _iso_scene(head)
    cam = Camera.anatomical(head, "anterior", zoom=1.1)
    phong = render_isosurface_mesh(scene, cam, (192, 192))
    gouraud = render_isosurface_mesh(scene, cam, (192, 192), MeshOptions(shading="gouraud"))
    save_row(raster_dir / "mesh_head_phantom_phong_gouraud.png", [phong, gouraud])
    hit = np.isfinite(phong.depth)
    assert 0.15 < hit.mean() < 0.9
    rows = np.nonzero(hit.any(axis=1))[0]
    assert rows.min() < 64 and rows.max() > 128  # skull near the top, jaw in the lower third
    # the bead on the patient's right (+x) projects onto the image's left half, the vertex above the nose
    marks = head.meta["truth"]["landmarks"]
    (col, _), depth = cam.project(np.asarray(marks["right_marker"], float), (192, 192))
    assert col < 96
    assert cam.project(np.asarray(marks["vertex"], float), (192, 192))[0][1] < \
        cam.project(np.asarray(marks["nose_tip"], float), (192, 192))[0][1]
    r, c = int(cam.project(np.asarray(marks["nose_tip"], float), (192, 192))[0][1]), 96
    assert hit[r - 3:r + 4, c - 3:c + 4].any()  # the face (nose) is drawn where it projects
    assert np.abs(phong.rgba - gouraud.rgba).mean() < 0.05
