"""The ray caster's shortcuts change no picture: normal codes, the projected footprint, the kept skip tables.

* Normals are stored as 16-bit octahedral direction codes (``raycast._normals``):
  every unit vector comes back within 1 degree (0.93 measured), a
  vanishing gradient as the zero vector, and on a sphere the decoded normals
  match the analytic radial direction.
* Only the tiles meeting the volume's projected footprint are traced
  (``_geometry.footprint``): tracing every tile gives the same outputs, for
  perspective and orthographic cameras, oblique views and an eye inside the box.
* The skip distances of a transfer function are kept per volume and reused
  (``Prepared.memo``): switching transfer functions back and forth draws what a
  fresh cache draws.
"""

from __future__ import annotations

import numpy as np
import pytest

from volumen.core import Camera, Scene, Shading, TransferFunction, Volume
from volumen.data import phantom
from volumen.render import default_transfer, render
from volumen.render.raycast import clear_cache
from volumen.render.raycast._cpu import TILE, frame_tiles
from volumen.render.raycast._frame import Outputs
from volumen.render.raycast._geometry import footprint
from volumen.render.raycast._march import render_tiles
from volumen.render.raycast._normals import (
    DIR_HALF,
    DIRS,
    NO_CODES,
    _decode_table,
    _encode,
    encode_normals,
    unpack,
)
from volumen.render.raycast._pack import pack_frame
from volumen.render.raycast._precompute import normal_params


def test_every_direction_comes_back_within_the_grid_bound():
    rng = np.random.default_rng(3)
    v = rng.normal(size=(20000, 3))
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    v = np.vstack([v, np.eye(3), -np.eye(3)])  # the octahedron's corners, where the fold is
    codes = np.array([_encode(x, y, z, 1.0) for x, y, z in v])
    exact = _decode_table()
    back = exact[codes]
    angle = np.degrees(np.arccos(np.clip(np.sum(back * v, axis=1), -1.0, 1.0)))
    print(f"octahedral codes: worst angular error {angle.max():.3f} deg, mean {angle.mean():.3f} deg")
    assert angle.max() < 1.0 and angle.mean() < 0.35
    assert np.allclose(np.linalg.norm(exact[1:], axis=1), 1.0, atol=1e-6)
    assert _encode(0.0, 0.0, 0.0, 0.0) == 0 and not exact[0].any()


def test_packed_directions_are_the_decoded_ones_to_half_a_level():
    """The kernels' table (one uint32 per code, 10 bits a component) against the float decode: every component
    within half a level (1 / (2 DIR_HALF)), code 0 exactly the zero vector."""
    exact, packed = _decode_table(), unpack(DIRS)
    err = np.abs(packed - exact).max()
    angle = np.degrees(np.arccos(np.clip(np.sum(packed[1:] * exact[1:], axis=1)
                                         / np.linalg.norm(packed[1:], axis=1), -1.0, 1.0)))
    print(f"packed directions: largest component error {err:.2e}, worst angle {angle.max():.3f} deg")
    assert DIRS.dtype == np.uint32 and DIRS.shape == (len(exact),)
    assert err <= 0.5 / DIR_HALF + 1e-12
    assert not packed[0].any()


def test_a_single_slice_volume_writes_only_the_codes_asked_for():
    """A single-slice volume has as many planes as the (1, 1, 1) placeholder of the codes not asked for: the
    kernel is told which to write (it wrote both, past the placeholder's end, when it guessed from the shapes:
    pydicom's CT_small.dcm then crashed the renderer). The slice's codes are those of the middle plane of three
    copies of it (the gradient along z is zero in both)."""
    x = np.arange(40, dtype=np.float64)
    plane = (10.0 * x[None, :] + 3.0 * x[:, None] ** 1.5).astype(np.int16)[None]  # (1, 40, 40)
    nrm, _ = normal_params(plane, np.eye(4), 1.0, False)
    codes, mags = encode_normals(plane, nrm, False, directions=True, magnitudes=False)
    assert mags.shape == (1, 1, 1) and not mags.any()
    stack = np.repeat(plane, 3, axis=0)
    want, _ = encode_normals(stack, normal_params(stack, np.eye(4), 1.0, False)[0], False)
    np.testing.assert_array_equal(codes[0], want[1])
    none, mags = encode_normals(plane, nrm, False, directions=False, magnitudes=True)
    assert none is NO_CODES and not NO_CODES.any() and mags.shape == plane.shape


def test_sphere_normals_are_radial():
    """Decoded codes of a ball (anisotropic spacing) point along the radius (world space) on its surface shell."""
    n, sp = 48, (1.5, 1.0, 0.8)  # (dz, dy, dx) mm
    z, y, x = np.meshgrid(*(np.arange(n) * s for s in sp), indexing="ij")
    c = (n - 1) / 2 * np.array(sp)
    r = np.sqrt((z - c[0]) ** 2 + (y - c[1]) ** 2 + (x - c[2]) ** 2)
    data = (1000.0 * np.clip(16.0 - r, -2.0, 2.0)).astype(np.int16)  # smooth ramp across the surface
    vol = Volume(data, spacing=sp)
    nrm, _ = normal_params(vol.data, vol.affine, 1.0, False)
    codes, mags = encode_normals(vol.data, nrm, False)
    assert mags.shape == (1, 1, 1)  # magnitudes only when asked for
    shell = np.abs(r - 16.0) < 0.5
    got = unpack(DIRS[codes[shell]])  # (gx, gy, gz) world
    want = -np.stack([x[shell] - c[2], y[shell] - c[1], z[shell] - c[0]], axis=1) / r[shell][:, None]
    angle = np.degrees(np.arccos(np.clip(np.sum(got * want, axis=1), -1, 1)))
    print(f"sphere shell ({shell.sum()} voxels): normal error mean {angle.mean():.2f} deg, p99 "
          f"{np.percentile(angle, 99):.2f} deg")
    assert np.percentile(angle, 99) < 3.0  # central differences on a sampled ball, plus the 0.5 deg grid


def _cameras(vol):
    base = Camera.orbit(vol, azimuth=30.0, elevation=20.0)
    ortho = Camera.orbit(vol, azimuth=-60.0, elevation=10.0).with_(projection="orthographic",
                                                                   parallel_scale=0.4 * vol.diagonal)
    inside = base.with_(position=tuple(vol.center), target=tuple(np.asarray(vol.center) + [0.0, 10.0, 0.0]))
    zoomed = Camera.orbit(vol, azimuth=10.0, zoom=3.0)
    return {"perspective": base, "orthographic": ortho, "eye inside": inside, "zoomed": zoomed}


@pytest.mark.parametrize("which", ["perspective", "orthographic", "eye inside", "zoomed"])
def test_footprint_traces_every_ray_that_meets_the_volume(which):
    vol = phantom("head", size=(40, 36, 32))
    cam = _cameras(vol)[which]
    scene = Scene(volume=vol, transfer=default_transfer(vol, "composite"), shading=Shading(mode="headlight"))
    size = (70, 54)
    render(scene, cam, size)  # the transparent cells are built from the second frame on: both below use them
    img = render(scene, cam, size)
    f = pack_frame(scene, cam, size)
    out = Outputs.empty(*size)
    samples, hits = render_tiles(frame_tiles(*size), TILE, f.arrays, f.settings, out, f.mode, f.light)
    x0, y0, x1, y1 = footprint(f.arrays.cam, f.arrays.geo)
    print(f"{which}: footprint x {x0}..{x1}, y {y0}..{y1} of {size}; hit rays {img.stats['rays_hit']}")
    np.testing.assert_array_equal(img.rgba, out.rgba)
    np.testing.assert_array_equal(img.depth, out.depth)
    assert img.stats["samples"] == samples == int(out.nsamp.sum())
    assert img.stats["rays_hit"] == hits == int(np.count_nonzero(out.nsamp))


@pytest.mark.parametrize("traced", [None, (20, 5, 41, 30), (0, 0, 0, 0), [3, 0, 11]])
def test_frame_tiles_take_every_tile_once_traced_first(traced):
    size = (70, 54)  # 5 x 4 tiles, the last column and row partial
    order = frame_tiles(*size, traced)
    n_traced = int((order[:, 1] == 0).sum())
    assert (order[:n_traced, 1] == 0).all() and (order[n_traced:, 1] > 0).all()
    tiles = [t for t, run in order for t in range(t, t + max(run, 1))]
    assert sorted(tiles) == list(range(20))
    assert all(t // 5 == (t + run - 1) // 5 for t, run in order[n_traced:])  # a blank run stays in its tile row
    # (20, 5, 41, 30) meets tile columns 1..2 (x 16..47) and rows 0..1 (y 0..31)
    assert n_traced == {"None": 20, "(20, 5, 41, 30)": 2 * 2, "(0, 0, 0, 0)": 0, "[3, 0, 11]": 3}[repr(traced)]


def test_kept_skip_tables_follow_the_transfer_function():
    vol = phantom("torso", size=(40, 36, 32))
    cam = Camera.orbit(vol, azimuth=20.0)
    a = Scene(volume=vol, transfer=TransferFunction.preset("ct-bone"))
    b = a.with_(transfer=TransferFunction.preset("ct-skin-bone"))
    clear_cache()
    seq = [render(s, cam, (48, 48)).rgba for s in (a, b, a, b)]
    clear_cache()
    fresh = [render(s, cam, (48, 48)).rgba for s in (a, b)]
    assert np.abs(fresh[0] - fresh[1]).max() > 0.1  # the two functions draw different pictures
    for got, want in zip(seq, fresh * 2, strict=True):
        np.testing.assert_array_equal(got, want)
