"""The per-voxel tables of a lit picture, in their smallest form: the normal codes of the shown bricks only
(``_normals.brick_codes``), light volumes within a share of the volume (``_lightvol.light_nodes``).

Checked against a second method: the codes kept for every brick (and ``encode_normals``' dense codes) draw the
same pictures to the bit; the bytes of the tables (not time) against the volume's own bytes on a torso CT
phantom large enough that the lattices' floor (``_params.MIN_NODES``) does not bound them.
"""

from __future__ import annotations

import numpy as np
import pytest

from volumen.core import Camera, Scene, Shading, TransferFunction, Volume
from volumen.data import phantom
from volumen.render import render
from volumen.render.raycast import _pack
from volumen.render.raycast._cache import clear_cache, prepare
from volumen.render.raycast._lightvol import light_nodes
from volumen.render.raycast._normals import BRICK, SPAN, brick_codes, brick_grid, encode_normals
from volumen.render.raycast._params import MIN_NODES, NODE_SHARE
from volumen.render.raycast._precompute import normal_params

#: the bars of the tables' bytes over the volume's: the headlight's codes and grids, and the lit models' (with the
#: three studio lights' lattices)
HEADLIGHT_BAR, LIT_BAR = 0.5, 1.5


def _ct(size) -> Volume:
    v = phantom("torso", size=size)
    return Volume(np.rint(v.data).astype(np.int16), spacing=v.spacing, affine=v.affine, modality="CT")


@pytest.fixture(scope="module")
def small():
    return _ct((48, 56, 64))


def _scene(vol, shading, preset="ct-bone"):
    return Scene(volume=vol, transfer=TransferFunction.preset(preset), shading=Shading(mode=shading))


@pytest.mark.parametrize("shading,preset", [("headlight", "ct-bone"), ("phong", "ct-skin-bone"),
                                            ("shadows", "ct-bone")])
def test_the_shown_bricks_codes_draw_the_picture_of_every_bricks_codes_to_the_bit(small, monkeypatch, shading,
                                                                                   preset):
    scene, cam = _scene(small, shading, preset), Camera.orbit(small, azimuth=30.0, elevation=20.0)
    clear_cache(small)
    sparse = render(scene, cam, (64, 64)).rgba
    kept = prepare(small)._codes
    (bricks, _), = kept.values()
    monkeypatch.setattr(_pack, "_shown", lambda *args: None)  # every brick
    dense = render(scene, cam, (64, 64)).rgba
    total = int(np.prod(brick_grid(small.data.shape)))
    shown = int(bricks.kept.sum())
    print(f"{shading} {preset}: {shown} of {total} bricks' codes kept")
    assert 0 < shown < total
    assert float(sparse[..., 3].max()) > 0.5  # a picture, not an empty frame
    np.testing.assert_array_equal(sparse, dense)


def test_a_kept_brick_holds_the_codes_every_voxel_gets_and_the_rest_hold_none(small):
    u = small.data
    nrm, _ = normal_params(u, small.affine, 1.0, False, magnitude=False)
    dense, _ = encode_normals(u, nrm, False)
    keep = np.zeros(brick_grid(u.shape), bool)
    keep[1, 2, 3] = keep[-1, -1, -1] = True
    codes = brick_codes(u, nrm, False, keep)
    assert codes.pool.shape == (3 * SPAN, SPAN, SPAN) and not codes.pool[:SPAN].any()
    for k, j, i in np.argwhere(keep):  # each brick holds SPAN voxels from its first, the volume's end clamped
        s = codes.slots[k, j, i]
        got = codes.pool[s * SPAN:(s + 1) * SPAN]
        want = dense[k * BRICK:k * BRICK + SPAN, j * BRICK:j * BRICK + SPAN, i * BRICK:i * BRICK + SPAN]
        np.testing.assert_array_equal(got[:want.shape[0], :want.shape[1], :want.shape[2]], want)
    assert (codes.slots[~keep] == 0).all()


def _tables_bytes(vol, shading) -> tuple[int, float]:
    """Bytes of the per-volume tables after a picture with ``shading`` (normal codes, block grids, memo'd tables,
    light volumes), and their multiple of the volume's bytes."""
    clear_cache(vol)
    render(_scene(vol, shading), Camera.orbit(vol), (32, 32))
    prep = prepare(vol)
    lights = getattr(prep, "light_set", None)
    n = prep.nbytes() + (0 if lights is None else int(lights.lvd.nbytes))
    return n, n / vol.data.nbytes


def test_the_tables_of_a_lit_picture_hold_a_share_of_the_volume():
    """The torso phantom made at 80 x 80 x 86 and each voxel repeated 4 times along each axis: 35 M voxels, past the
    lattices' floor (NODE_SHARE of its voxels above MIN_NODES), the same share of bone, cheap to make."""
    small = _ct((80, 80, 86))
    data = small.data.repeat(4, axis=0).repeat(4, axis=1).repeat(4, axis=2)
    vol = Volume(data, spacing=tuple(s / 4 for s in small.spacing), modality="CT")
    assert light_nodes(vol.data.shape) == NODE_SHARE * vol.data.size > MIN_NODES
    ratios = {}
    for shading in ("headlight", "shadows", "scattering"):
        n, ratios[shading] = _tables_bytes(vol, shading)
        print(f"{shading}: tables {n / 2**20:.1f} MiB, {ratios[shading]:.2f}x the volume")
    assert ratios["headlight"] <= HEADLIGHT_BAR
    assert ratios["shadows"] <= LIT_BAR and ratios["scattering"] <= LIT_BAR


def test_a_picture_that_reads_no_light_volumes_frees_them(small):
    clear_cache(small)
    render(_scene(small, "shadows"), Camera.orbit(small), (16, 16))
    assert prepare(small).light_set is not None
    render(_scene(small, "headlight"), Camera.orbit(small), (16, 16))
    assert prepare(small).light_set is None


def test_the_codes_are_kept_while_they_hold_a_frames_bricks_and_built_again_for_far_fewer(small):
    """A frame that shows bricks the kept codes lack builds them again; one that shows a part of them keeps them,
    unless they hold more than ``SLACK`` times its bricks (then only its own are built: the rest freed)."""
    clear_cache(small)
    prep = prepare(small)
    grid = brick_grid(small.data.shape)
    wide = np.ones(grid, bool)
    few = np.zeros(grid, bool)
    few[0, 0, :2] = True
    pool, slots, _ = prep.codes(False, True, False, wide)
    assert prep.codes(False, True, False, wide)[0] is pool  # the same bricks: kept
    assert prep.codes(False, True, False, None)[0] is pool  # every brick: what it holds
    narrow, narrow_slots, _ = prep.codes(False, True, False, few)
    assert narrow is not pool and narrow.shape[0] == (few.sum() + 1) * SPAN
    assert (narrow_slots[few] > 0).all() and (narrow_slots[~few] == 0).all()
    assert prep.codes(False, True, False, wide)[0].shape == pool.shape  # shown again: built again
