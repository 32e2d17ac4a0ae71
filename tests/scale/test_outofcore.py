"""Out-of-core (bricked) ray casting equals the in-memory render; empty bricks skipped (peak memory: test_memory).

A chunked volume (``volumen.load`` of an OME-Zarr image) goes through ``volumen.render`` itself; a path or a Volume
in memory through ``volumen.scale.render_bricked``."""

from dataclasses import replace

import numpy as np
import pytest

import volumen
from volumen.core import Camera, Sampling, Scene, Shading, TransferFunction, Volume
from volumen.render import render

pytest.importorskip("zarr", reason="the scale extra (zarr) is not installed")
from volumen.scale import render_bricked

TOL = 1e-5


def _blob(shape=(50, 44, 38), noise=30.0, seed=0):
    z, y, x = np.indices(shape)
    c = np.array(shape) / 2
    r2 = (z - c[0]) ** 2 + (y - c[1]) ** 2 + (x - c[2]) ** 2
    d = 1000 * np.exp(-r2 / (0.02 * np.prod(shape) ** (2 / 3))) + np.random.default_rng(seed).normal(0, noise, shape)
    return d.astype(np.int16)


def _scene(v, mode, opacity=0.6, **smp):
    """Default sampling (jitter, early termination at 0.99, no lattice) at 1.7 samples a voxel, at full rate as
    bricks drawn out of core sample (the in-memory picture is the reference)."""
    tf = TransferFunction.window_level(600, 500, opacity=(0.0, opacity))
    return Scene(volume=v, transfer=tf, mode=mode,
                 sampling=Sampling(samples_per_voxel=1.7, seed=3, **{"adaptive": False, **smp}))


@pytest.fixture(scope="module")
def zarr_blob(tmp_path_factory):
    v = Volume(_blob(), spacing=(1.0, 0.9, 1.1))
    p = tmp_path_factory.mktemp("ooc") / "blob.ome.zarr"
    volumen.save(v, p, chunks=16)
    return v, p


@pytest.mark.parametrize("mode", ["composite", "mip"])
@pytest.mark.parametrize("projection", ["perspective", "orthographic"])
def test_bricked_equals_in_memory(zarr_blob, mode, projection):
    """Lit (the default headlight: normals from the one-voxel pad) composite, and MIP, on a noisy blob, with the
    default sampling: jittered, early ray termination at 0.99 -- which changes the composite picture by more
    than 1e-3 (so it is exercised): the bricks carry each ray's opacity from front to back."""
    v, p = zarr_blob
    scene = _scene(v, mode)
    cam = Camera.orbit(v, azimuth=30, elevation=20).with_(projection=projection)
    ref = render(scene, cam, (80, 72))
    chunked = volumen.load(p)
    out = render(scene.with_(volume=chunked), cam, (80, 72), memory="64KB", brick=16)
    assert out.stats["bricks_drawn"] == out.stats["bricks"] == 36
    assert 0 < out.stats["cache_peak_bytes"] <= 64 << 10  # 8 chunks of 16^3 int16 at most
    assert out.stats["renderer"] == {"device": "cpu", "technique": "raycast"}
    # the volume's own view read only the three planes of its table range's sample (``core.table_range``, once,
    # not each frame: its minimum is negative); the bricks read the cache
    planes = chunked.data.stats["chunk_reads"]
    assert planes == 3 * 3 * 3  # three planes of 3 x 3 chunks each, read once (``core.strided_values`` keeps them)
    render(scene.with_(volume=chunked), cam, (80, 72), memory="64KB", brick=16)
    assert chunked.data.stats["chunk_reads"] == planes
    assert ref.rgba[..., 3].max() > 0.5  # something is drawn
    if mode == "composite":
        full = render(scene.with_(sampling=replace(scene.sampling, early_termination=1.0)), cam, (80, 72))
        assert np.abs(full.rgba - ref.rgba).max() > 1e-3
    np.testing.assert_allclose(out.rgba, ref.rgba, atol=TOL)
    if mode == "mip":
        np.testing.assert_allclose(out.value, ref.value, atol=TOL * 1000)  # data units (HU): 1e-5 of the range
        np.testing.assert_array_equal(np.isnan(out.value), np.isnan(ref.value))


def test_bricked_phong_lit_by_the_whole_volumes_studio_rig(zarr_blob):
    """Phong with no scene lights is lit by the studio rig, placed about the whole volume: each brick, a Volume of
    its own, placed it about its own centre (pixels differed by up to 0.049 here)."""
    v, p = zarr_blob
    scene = _scene(v, "composite").with_(shading=Shading(mode="phong"))
    cam = Camera.orbit(v, azimuth=30, elevation=20)
    ref = render(scene, cam, (48, 48))
    out = render(scene.with_(volume=volumen.load(p)), cam, (48, 48), brick=16)
    assert out.stats["bricks_drawn"] > 1 and ref.rgba[..., 3].max() > 0.5
    np.testing.assert_allclose(out.rgba, ref.rgba, atol=TOL)


def test_oblique_volume_in_memory_source():
    """An oblique affine (voxel crops per brick), a Volume held in memory as the source, lattice sampling."""
    a = np.array([[0.8, -0.5, 0, 3.0], [0.5, 0.8, 0, -2.0], [0, 0, 1.2, 1.0], [0, 0, 0, 1]])
    a[:3, :3] /= np.linalg.norm(a[:3, :3], axis=0)
    a[:3, :3] *= [1.1, 0.9, 1.0]
    v = Volume(_blob((40, 36, 30)), spacing=(1.0, 0.9, 1.1), affine=a)
    scene = _scene(v, "composite", lattice=True)
    cam = Camera.orbit(v, azimuth=-50, elevation=35)
    ref = render(scene, cam, (64, 64))
    out = render_bricked(v, scene, cam, (64, 64), brick=12)
    np.testing.assert_allclose(out.rgba, ref.rgba, atol=TOL)


def test_empty_bricks_skipped_without_reading(tmp_path):
    d = np.zeros((64, 64, 64), np.int16)
    d[8:24, 40:56, 20:36] = _blob((16, 16, 16), noise=0) + 200
    v = Volume(d)
    p = tmp_path / "sparse.ome.zarr"
    volumen.save(v, p, chunks=16)
    scene = _scene(v, "composite").with_(shading=Shading(mode="none"))  # unlit: bricks read no extra voxel
    cam = Camera.orbit(v, azimuth=20, elevation=10)
    # the stored per-chunk ranges travel with the chunked volume's data: skipped bricks are not read
    out = render(scene.with_(volume=volumen.load(p)), cam, (64, 64), brick=16)
    np.testing.assert_allclose(out.rgba, render(scene, cam, (64, 64)).rgba, atol=TOL)
    # a brick reads its chunk and the first voxel of the next (the shared face): along each axis the blob's
    # chunks (z 0-1, y 2-3, x 1-2 of 16) are read by bricks z 0-1, y 1-3, x 0-2 -> 2 * 3 * 3 = 18 of 64
    assert out.stats["bricks_drawn"] == 18, out.stats
    assert out.stats["bricks_skipped"] == 64 - 18
    assert out.stats["chunk_reads"] == 3 * 3 * 4  # chunks z 0-2, y 1-3, x 0-3 of 4 x 4 x 4


def test_coarse_level_while_interacting(zarr_blob):
    """pick_level: one voxel per pixel or fewer while interacting, full resolution when idle; the coarse level
    drawn out of core equals the in-memory render of that level."""
    from volumen.io import open_levels
    from volumen.scale import pick_level

    v, p = zarr_blob
    levels, _ = open_levels(p)
    assert [lv.shape for lv in levels] == [(50, 44, 38), (25, 22, 19), (13, 11, 10)]  # down to one chunk of 16
    assert pick_level(levels, (32, 32), interacting=True) == 1
    assert pick_level(levels, (64, 64), interacting=True) == 0
    assert pick_level(levels, (32, 32), interacting=False) == 0
    coarse = volumen.load(p, level=1)
    c = Volume(np.asarray(coarse.data), spacing=coarse.spacing, affine=coarse.affine)
    scene = _scene(c, "mip")
    cam = Camera.orbit(v, azimuth=30, elevation=20)
    out = render_bricked(p, scene, cam, (48, 48), level=1, brick=8)
    np.testing.assert_allclose(out.rgba, render(scene, cam, (48, 48)).rgba, atol=TOL)


def test_moved_camera_reuses_the_bricks(zarr_blob):
    """The second frame of one chunked volume, the camera moved, reads and decodes no chunk and prepares no
    brick again (samples, normal codes, skip blocks come from the chunk cache), within the cache's bound; its
    picture equals the in-memory one."""
    v, p = zarr_blob
    scene = _scene(v, "composite")
    chunked = scene.with_(volume=volumen.load(p))
    first = render(chunked, Camera.orbit(v, azimuth=30, elevation=20), (80, 72), memory="1MB", brick=16)
    assert first.stats["chunk_reads"] > 0 and first.stats["normals_encoded"] == first.stats["bricks_drawn"] == 36
    cam = Camera.orbit(v, azimuth=60, elevation=5)
    out = render(chunked, cam, (80, 72), memory="1MB", brick=16)
    built = {k: out.stats[k] for k in ("chunk_reads", "bricks_prepared", "normals_encoded", "skip_blocks_built")}
    assert out.stats["bricks_drawn"] == 36 and built == dict.fromkeys(built, 0), out.stats
    assert out.stats["cache_bytes"] <= out.stats["cache_peak_bytes"] <= 1 << 20
    np.testing.assert_allclose(out.rgba, render(scene, cam, (80, 72)).rgba, atol=TOL)


def test_a_fill_far_below_draws_out_of_core_as_without_it(tmp_path):
    """A resampler's fill outside the field of view (``data.fill_outside_field``), as OME-Zarr drawn out of core:
    a float MRI filled with -1e6, an int16 MRI filled with -32768 and a float CT filled with the lowest float
    draw as the same chunked scan filled with 0 (the CT: -1024 HU), within 0.005 (measured 0.00014-0.0027).
    The bricks' tables span the whole volume's ``table_range`` (its display range's bottom, cut above the fill,
    is read on the chunked volume's three planes), and a brick holding the fill clamps it in a copy of its
    samples, never reading past the table. Before, their tables spanned the fill: 0.14-0.25 (a milky field of
    view) and 0.095 for the CT."""
    from volumen.data import fill_outside_field, phantom
    from volumen.render import default_transfer

    def chunked(src, fill, dtype=np.float32):
        v = fill_outside_field(src, fill)
        v = Volume(v.data.astype(dtype), spacing=v.spacing, affine=v.affine, modality=v.modality, units=v.units)
        volumen.save(v, tmp_path / f"{src.name}{fill:g}{np.dtype(dtype).name}.ome.zarr", chunks=16)
        return volumen.load(tmp_path / f"{src.name}{fill:g}{np.dtype(dtype).name}.ome.zarr")

    def picture(vol, shading):
        scene = Scene(volume=vol, transfer=default_transfer(vol, "composite"), shading=Shading(mode=shading))
        return render(scene, Camera.orbit(vol, view="left"), (96, 96), memory="64MB").rgba

    mr = phantom("mr_head", size=64, dtype="float32")
    ct = phantom("head", size=64)
    for src, base, fill, dtype, shading in ((mr, 0.0, -1e6, np.float32, "none"), (mr, 0.0, -32768.0, np.int16, "none"),
                                            (ct, -1024.0, float(np.finfo(np.float32).min), np.float32, "headlight")):
        a, b = picture(chunked(src, base, dtype), shading), picture(chunked(src, fill, dtype), shading)
        diff = float(np.abs(a - b).mean())
        print(f"{src.name} {np.dtype(dtype).name} fill {fill:g}: mean RGB {a[..., :3].mean():.4f} / "
              f"{b[..., :3].mean():.4f}, mean |diff| {diff:.5f}")
        assert a[..., 3].max() > 0.5 and diff <= 0.005
