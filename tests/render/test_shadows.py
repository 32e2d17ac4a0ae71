"""Shadows: the illumination volumes (``fast``) against direct shadow rays (the reference definition).

Both implement docs/design.md section 3: the light reaching a sample is
``1 - opacity accumulated`` from ``shadow_offset`` voxels off the sample toward
the light, stopping at the light or the clip box. Tolerances: mean
absolute difference <= 0.01 and 99th percentile <= 0.05 per channel, and the
umbra of an opaque sphere on a slab where geometry puts it, within one voxel.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

from tests.render.render_helpers import axis_camera
from volumen.core import Camera, Clipping, ClipPlane, Light, Sampling, Scene, Shading, TransferFunction, Volume
from volumen.data import phantom
from volumen.render import render

SIZE = (64, 64)


def _spot_upper_right(volume, camera, distance=1.2):
    """A spot light from the picture's upper right (and in front), aimed at the volume's centre."""
    r, u, f = camera.basis()
    c = np.asarray(volume.center)
    pos = c + volume.diagonal * distance * (0.6 * r + 0.6 * u - 0.5 * f)
    return Light(position=tuple(pos), direction=tuple(c - pos), exponent=2.0, intensity=1.1, kind="spot")


def _compare(a, b):
    d = np.abs(a.rgba - b.rgba).reshape(-1, 4)
    return d.mean(axis=0), np.percentile(d, 99, axis=0)


@pytest.fixture(scope="module")
def head():
    return phantom("head", size=64)


@pytest.fixture(scope="module")
def torso():
    return phantom("torso", size=64)


CASES = {
    "head": ("head", "ct-skin-bone", None),
    "head-cropped": ("head", "ct-bone", Clipping(crop=(0, 30, 0, 60, 0, 63),
                                                  planes=(ClipPlane(point=(0, 0, 10), normal=(0.2, 0.1, -1)),))),
    "torso": ("torso", "ct-bone", None),
    "torso-soft": ("torso", "ct-soft-tissue", None),
}


@pytest.mark.parametrize("case", list(CASES))
def test_fast_matches_direct_on_phantoms(case, request, output_dir):
    name, preset, clipping = CASES[case]
    vol = request.getfixturevalue(name)
    cam = Camera.orbit(vol, azimuth=-20, elevation=10, zoom=1.1)
    scene = Scene(volume=vol, transfer=TransferFunction.preset(preset), lights=(_spot_upper_right(vol, cam),),
                  clipping=clipping or Clipping(), sampling=Sampling(seed=1))
    direct = render(scene.with_(shading=Shading(mode="shadows", shadow_method="direct")), cam, SIZE)
    fast = render(scene.with_(shading=Shading(mode="shadows", shadow_method="fast")), cam, SIZE)
    phong = render(scene.with_(shading=Shading(mode="phong")), cam, SIZE)
    out = output_dir / "lighting"
    out.mkdir(exist_ok=True)
    for tag, im in (("direct", direct), ("fast", fast), ("phong", phong)):
        im.save(out / f"shadows_{case}_{tag}.png")
    mae, p99 = _compare(fast, direct)
    assert np.all(mae <= 0.01) and np.all(p99 <= 0.05), (mae, p99)
    # the shadows are there: the lights do not just pass through
    assert np.abs(phong.rgba - direct.rgba)[..., :3].mean() > 5 * mae[:3].max(), (mae, phong.rgba.mean())
    assert fast.stats["light_volumes_built"] == 1


def _sphere_over_slab(n=64, centre=(40.0, 34.0, 36.0), radius=7.0, top=14.0):
    z, y, x = np.mgrid[:n, :n, :n].astype(np.float64)
    r = np.sqrt((x - centre[0]) ** 2 + (y - centre[1]) ** 2 + (z - centre[2]) ** 2)
    inside = np.maximum(0.5 * (1 - np.tanh((r - radius) / 0.7)), 0.5 * (1 - np.tanh((z - top) / 0.7)) * (z > 4))
    data = np.rint(-1000 + 2000 * inside).astype(np.int16)  # HU as CT stores them: the phantoms' int16 kernels
    return Volume(data, spacing=(1.0, 1.0, 1.0), modality="CT", units="HU")


OPAQUE = TransferFunction(color=((-1000, 0.9, 0.9, 0.9), (1000, 0.9, 0.9, 0.9)),
                          opacity=((-1000, 0), (-150, 0), (150, 1.0), (1000, 1.0)))


def _analytic_umbra(light, centre, radius, top, size):
    """Pixels (superior view: column = x, row = ny - 1 - y) of the plane z = top whose segment to the light
    crosses the sphere."""
    w, h = size
    cols, rows = np.meshgrid(np.arange(w, dtype=float), np.arange(h, dtype=float))
    q = np.stack([cols, (h - 1) - rows, np.full_like(cols, top)], axis=-1)
    p = np.asarray(light, float)
    d = p - q
    L = np.linalg.norm(d, axis=-1, keepdims=True)
    d = d / L
    c = np.asarray(centre, float) - q
    s = np.clip(np.sum(c * d, axis=-1), 0, L[..., 0])
    closest = c - s[..., None] * d
    return np.linalg.norm(closest, axis=-1) < radius


def test_sphere_umbra_where_geometry_puts_it(output_dir):
    centre, radius, top = (40.0, 34.0, 36.0), 7.0, 14.0
    vol = _sphere_over_slab(centre=centre, radius=radius, top=top)
    cam, size = axis_camera(vol, "superior")
    light_pos = (40.0 + 95.0, 34.0 + 30.0, 36.0 + 80.0)
    light = Light(position=light_pos, direction=(-95, -30, -80), exponent=1.0)
    scene = Scene(volume=vol, transfer=OPAQUE, lights=(light,), sampling=Sampling(jitter=False))
    ims = {m: render(scene.with_(shading=Shading(mode="shadows", shadow_method=m, specular=0.0)), cam, size)
           for m in ("direct", "fast")}
    phong = render(scene.with_(shading=Shading(mode="phong", specular=0.0)), cam, size)
    out = output_dir / "lighting"
    out.mkdir(exist_ok=True)
    for m, im in ims.items():
        im.save(out / f"sphere_slab_{m}.png")
    mae, p99 = _compare(ims["fast"], ims["direct"])
    assert np.all(mae <= 0.01) and np.all(p99 <= 0.05), (mae, p99)

    # the slab's visible top: away from the sphere's footprint (as seen from above) and the picture's border
    cols, rows = np.meshgrid(np.arange(size[0]), np.arange(size[1]))
    foot = np.hypot(cols - centre[0], (size[1] - 1 - rows) - centre[1]) < radius + 2
    foot |= (cols == 0) | (rows == 0) | (cols == size[0] - 1) | (rows == size[1] - 1)  # the box's own edge
    umbra = _analytic_umbra(light_pos, centre, radius, top, size)
    lit_level = np.median(phong.rgba[..., 0][~foot & ~umbra])
    dark_level = 0.9 * 0.15  # ambient only
    assert lit_level > dark_level + 0.2
    inner = ndimage.binary_erosion(umbra, iterations=1)
    outer = ndimage.binary_dilation(umbra, iterations=1)
    assert inner.sum() > 40  # a real umbra, in the picture
    for m, im in ims.items():
        shadowed = im.rgba[..., 0] < 0.5 * (lit_level + dark_level)
        wrong = (shadowed & ~outer) | (~shadowed & inner)
        assert not np.any(wrong & ~foot), (m, np.argwhere(wrong & ~foot)[:10])
        # outside the umbra the slab is lit exactly as without shadows: no self-shadowing
        far = ~ndimage.binary_dilation(umbra, iterations=3) & ~foot
        assert np.abs(im.rgba[..., 0] - phong.rgba[..., 0])[far].max() < 0.02, m


def test_clip_box_stops_the_light_path():
    """A sphere cropped away casts no shadow: the path to the light stops at the clip box, so the picture
    is the one of the slab alone."""
    centre, radius, top = (40.0, 34.0, 36.0), 7.0, 14.0
    vol = _sphere_over_slab(centre=centre, radius=radius, top=top)
    slab = _sphere_over_slab(centre=centre, radius=0.0, top=top)
    cam, size = axis_camera(vol, "superior")
    light = Light(position=(135.0, 64.0, 116.0))
    crop = Clipping(crop=(0, 63, 0, 63, 0, 24))
    for m in ("direct", "fast"):
        scene = Scene(volume=vol, transfer=OPAQUE, lights=(light,), sampling=Sampling(jitter=False),
                      clipping=crop, shading=Shading(mode="shadows", shadow_method=m))
        im = render(scene, cam, size)
        alone = render(scene.with_(volume=slab), cam, size)
        assert np.abs(im.rgba - alone.rgba).max() < 1e-5, m
        # without the crop the same light does cast a shadow
        full = render(scene.with_(clipping=Clipping()), cam, size)
        assert (im.rgba[..., 0] - full.rgba[..., 0]).max() > 0.2, m


def test_light_volume_rebuilt_only_when_its_inputs_change(head):
    cam = Camera.orbit(head, azimuth=30)
    light = _spot_upper_right(head, cam)
    scene = Scene(volume=head, transfer=TransferFunction.preset("ct-bone"), lights=(light,),
                  shading=Shading(mode="shadows"))
    two = scene.with_(lights=(light, Light(position=(0, 500, 0))))
    builds = [render(scene, cam, (24, 24)).stats["light_volumes_built"],
              render(scene, Camera.orbit(head, azimuth=-60), (24, 24)).stats["light_volumes_built"],
              render(two, cam, (24, 24)).stats["light_volumes_built"],
              render(two.with_(transfer=TransferFunction.preset("ct-skin-bone")), cam, (24, 24))
              .stats["light_volumes_built"],
              render(scene.with_(clipping=Clipping(crop=(0, 40, 0, 60, 0, 63))), cam, (24, 24))
              .stats["light_volumes_built"]]
    # first build; a new camera reuses it; a second light adds one (the first one's volume is kept); a new
    # transfer function rebuilds both; a new clip box rebuilds
    assert builds == [1, 0, 1, 2, 1], builds
