"""The prefetch hints (``volumen.jit.prefetch``): the march asks for the cache lines of the sample a few steps ahead
(``_march._ahead``), a light path for its lattice nodes before its near march (``_lightvol.lattice_ahead``), and
nothing else changes.

A hint changes no value: the whole-abdomen CT's frames and lattices came out the same to the bit as before the
hints (their MD5s, docs/design.md section 6). Run as Python (``NUMBA_DISABLE_JIT``, the CUDA simulator of
``test_cuda_sim.py``) ``prefetch`` does nothing, and the GPU kernels compile it to nothing
(``test_cuda_backend.py``'s PTX check). What it buys is measured, not asserted: a Phong frame of that CT took
about 0.9x the time it took without it.
"""

from __future__ import annotations

import re

import numpy as np
import pytest
from numba import njit

from volumen.core import Camera, Scene, Shading, TransferFunction
from volumen.data import organ_phantom
from volumen.jit import prefetch
from volumen.render.raycast._lightvol import NO_SITE, lattice_ahead, lattice_read
from volumen.render.raycast._march import _ahead
from volumen.render.raycast._pack import pack_frame
from volumen.render.raycast._pieces import Phong, Unlit
from volumen.render.raycast._ray import begin_ray
from volumen.render.raycast._sample import prefetch_cell

HINT = re.compile(r"call void @llvm\.prefetch")


def test_the_hint_compiles_to_a_prefetch_and_changes_no_value():
    vol = np.arange(4 * 5 * 6, dtype=np.int16).reshape(4, 5, 6)
    read = njit(lambda v, k, j, i: (prefetch(v, (k, j, i)), v[k, j, i])[1])
    assert read(vol, 3, 4, 5) == vol[3, 4, 5]
    assert len(HINT.findall(read.inspect_llvm(read.signatures[0]))) == 1
    assert prefetch(vol, (0, 0, 0)) is None  # Python: nothing (NUMBA_DISABLE_JIT, the CUDA simulator)


def test_a_cell_asks_for_its_four_rows_inside_the_array_wherever_the_position():
    """Positions outside the array are clamped, as the samplers clamp them: the hint never points outside it."""
    vol = np.zeros((3, 4, 5), np.uint16)
    cell = njit(lambda v, x, y, z: prefetch_cell(v, x, y, z))
    for pos in ((1.5, 2.5, 0.5), (-7.0, 1e9, -1e9), (4.0, 3.0, 2.0)):
        cell(vol, *pos)
    assert len(HINT.findall(cell.inspect_llvm(cell.signatures[0]))) == 4


def test_the_march_asks_for_the_normal_codes_only_where_the_light_shades_with_normals():
    vol, _ = organ_phantom(16, spacing=2.0)
    scene = Scene(volume=vol, transfer=TransferFunction.preset("ct-soft-tissue", value_range=vol.value_range()),
                  shading=Shading(mode="phong"))
    frame = pack_frame(scene, Camera.orbit(vol), (8, 8))
    a, s = frame.arrays, frame.settings
    ahead = njit(lambda a, s, light: _ahead(begin_ray(4, 4, a, s), a, s, 1.0, light))
    counts = {}
    for light in (Phong(), Unlit()):
        ahead(a, s, light)
        sig = [g for g in ahead.signatures if type(g[-1].instance_class()) is type(light)]
        counts[type(light)] = len(HINT.findall(ahead.inspect_llvm(sig[0])))
    # the scan's cell, the codes' where the light shades with normals, the gradient magnitudes' under gradient opacity
    assert counts == {Phong: 12, Unlit: 8}


def test_a_light_path_asks_for_its_lattice_nodes_before_its_near_march():
    """``light_visibility`` finds where the lattice will be read first, asks for those node rows (two per slice), and
    reads them after the march; a site that reads nothing gives transmittance 1 and asks for nothing."""
    lvd = np.linspace(0.0, 1.0, 2 * 3 * 4)
    ahead = njit(lambda lvd, site: lattice_ahead(lvd, site))
    read = njit(lambda lvd, site: lattice_read(lvd, site))
    ahead(lvd, NO_SITE)
    assert len(HINT.findall(ahead.inspect_llvm(ahead.signatures[0]))) == 4
    assert read(lvd, NO_SITE) == 1.0
    site = (1, 0.25, 0.5, 13, 0.25, 0.5, 0.75, 4)  # nodes 1, 2, 5, 6 of slice 0 and 13, 14, 17, 18 of slice 1
    bilinear = [(1 - 0.5) * ((1 - 0.25) * lvd[i] + 0.25 * lvd[i + 1]) + 0.5 * ((1 - 0.25) * lvd[i + 4] +
                                                                             0.25 * lvd[i + 5]) for i in (1, 13)]
    assert read(lvd, site) == pytest.approx(0.25 * bilinear[0] + 0.75 * bilinear[1], abs=1e-15)
