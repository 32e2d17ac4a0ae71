"""The march's prefetch hint (``volumen.jit.prefetch``, ``_march._ahead``): the cache lines of the sample a few steps
ahead are asked for, and nothing else changes.

A hint changes no value, so the pictures are the same to the bit with or without it (the compiled kernels against
their Python source run in ``test_cuda_sim.py``, where ``prefetch`` is a Python function that does nothing; the
GPU kernels compile it to nothing, ``test_cuda_backend.py``'s PTX check). What it buys is measured, not asserted:
a Phong frame of the whole-abdomen CT took about 0.9x the time it took without it (docs/design.md section 6).
"""

from __future__ import annotations

import re

import numpy as np
from numba import njit

from volumen.core import Camera, Scene, Shading, TransferFunction
from volumen.data import organ_phantom
from volumen.jit import prefetch
from volumen.render.raycast._march import _ahead
from volumen.render.raycast._pack import pack_frame
from volumen.render.raycast._pieces import Phong, Unlit
from volumen.render.raycast._ray import begin_ray
from volumen.render.raycast._sample import prefetch_cell

HINT = re.compile(r"call void @llvm\.prefetch")


def test_the_hint_compiles_to_a_prefetch_and_changes_no_value():
    vol = np.arange(4 * 5 * 6, dtype=np.int16).reshape(4, 5, 6)
    read = njit(lambda v, k, j, i: (prefetch(v, k, j, i), v[k, j, i])[1])
    assert read(vol, 3, 4, 5) == vol[3, 4, 5]
    assert len(HINT.findall(read.inspect_llvm(read.signatures[0]))) == 1
    assert prefetch(vol, 0, 0, 0) is None  # Python: nothing (NUMBA_DISABLE_JIT, the CUDA simulator)


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
