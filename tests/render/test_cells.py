"""Pre-classified cells (``raycast._cells``, issue 27 item 2): the marching loop passes over the samples of voxel
cells whose values all classify transparent. The bits match a brute-force count, and the pictures do not change
(bit for bit), with fewer samples taken."""

from __future__ import annotations

import numpy as np
import pytest

from volumen.core import Camera, Sampling, Scene, TransferFunction
from volumen.data import phantom
from volumen.render.raycast._cells import cell_bits
from volumen.render.raycast._cpu import _draw
from volumen.render.raycast._geometry import footprint
from volumen.render.raycast._pack import pack_frame
from volumen.render.raycast._tiles import frame_tiles


def _brute_bits(u, u0, ufac, alpha):
    """Per cell (clamped at the far borders): does some table entry ``int(v + 0.5)`` of a value ``v`` between the
    8 corners' extremes have ``alpha > 0``."""
    nz, ny, nx = u.shape
    top = alpha.shape[0] - 1
    want = np.zeros((nz, ny, nx), bool)
    for k in range(nz):
        for j in range(ny):
            for i in range(nx):
                c = u[k:min(k + 2, nz), j:min(j + 2, ny), i:min(i + 2, nx)]
                e0 = min(max(int((c.min() - u0) * ufac + 0.5), 0), top)
                e1 = min(max(int((c.max() - u0) * ufac + 0.5), 0), top)
                want[k, j, i] = (alpha[e0:e1 + 1] > 0).any()
    return want


def test_cell_bits_match_a_brute_force_classification():
    rng = np.random.default_rng(7)
    u = rng.integers(-200, 800, size=(6, 7, 21)).astype(np.int16)  # 21: a partial last byte along x
    u[:3] = 10  # a homogeneous part: cells of one value
    alpha = np.zeros(100, np.float32)
    alpha[[3, 40, 41, 42, 97]] = 0.5
    u0, ufac = -200.0, 99.0 / 1000.0
    bits = cell_bits(u, u0, ufac, alpha)
    got = np.unpackbits(bits, axis=2, bitorder="little")[:, :, :21].astype(bool)
    want = _brute_bits(u, u0, ufac, alpha)
    assert want.any() and not want.all()
    np.testing.assert_array_equal(got, want)


@pytest.mark.parametrize("adaptive", [False, True])
@pytest.mark.parametrize("preset", ["ct-bone", "ct-skin-bone"])
def test_passing_over_transparent_cells_changes_no_pixel(preset, adaptive):
    """The whole-abdomen phantom, a CT preset, the default headlight, jitter and early termination, full rate and
    adaptive: the same frame drawn with and without the cells is bit-identical (colour, opacity, depth) and
    takes fewer samples (measured at 96x96: ct-bone 61-66 % fewer, ct-skin-bone 20-24 %)."""
    vol = phantom("abdomen", size=(112, 101, 122))
    scene = Scene(volume=vol, transfer=TransferFunction.preset(preset), sampling=Sampling(adaptive=adaptive))
    f = pack_frame(scene, Camera.orbit(vol), (96, 96))
    assert f.settings.cells
    order = frame_tiles(96, 96, footprint(f.arrays.cam, f.arrays.geo))
    with_cells, (n_cells, _), _ = _draw(f, order)
    without, (n_all, _), _ = _draw(f, order, settings=f.settings._replace(cells=False))
    np.testing.assert_array_equal(with_cells.rgba, without.rgba)
    np.testing.assert_array_equal(with_cells.depth, without.depth)
    print(f"{preset} adaptive={adaptive}: samples {n_all} -> {n_cells} ({100 * (1 - n_cells / n_all):.0f} % fewer)")
    assert with_cells.rgba[..., 3].max() > 0.5  # something is drawn
    assert n_cells < 0.9 * n_all


def test_no_cells_where_a_sample_needs_its_neighbour_or_leaves_the_corners_range():
    vol = phantom("abdomen", size=(56, 50, 61))
    cam = Camera.orbit(vol)
    for sampling in (Sampling(preintegrate=True), Sampling(interpolation="bspline"), Sampling(skip_empty=False)):
        f = pack_frame(Scene(volume=vol, transfer=TransferFunction.preset("ct-bone"), sampling=sampling), cam, (8, 8))
        assert not f.settings.cells and f.arrays.cells.size == 1
