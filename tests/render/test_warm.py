"""Kernels compiled in child processes are the ones this process then draws with (``volumen.render.warm``)."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

from numba.core import event

from volumen.core import Camera, Clipping, Scene, Shading, TransferFunction
from volumen.data import phantom
from volumen.render import render
from volumen.render._warm import WARM_EDGE, kernel_key, warm_scene


class _Compiled(event.Listener):
    """The modules of the functions Numba compiles (not those it loads from its cache)."""

    def __init__(self):
        self.modules = []

    def on_start(self, ev):
        fn = getattr((ev.data or {}).get("dispatcher"), "py_func", None)
        self.modules.append(getattr(fn, "__module__", "") or "")

    def on_end(self, ev):
        pass


def test_the_cropped_scene_compiles_nothing_the_scene_did_not():
    vol = phantom("head", size=(64, 60, 56))
    scene = Scene(volume=vol, transfer=TransferFunction.preset("ct-bone"), shading=Shading(mode="headlight"))
    cam = Camera.orbit(vol)
    render(scene, cam, (16, 16))
    small = warm_scene(scene)
    assert max(small.volume.shape) == WARM_EDGE and small.volume.dtype == vol.dtype
    assert kernel_key(small) == kernel_key(scene)
    seen = _Compiled()
    with event.install_listener("numba:compile", seen):
        render(small, cam, (16, 16))
    assert not [m for m in seen.modules if m.startswith("volumen.")]


def test_every_sample_type_shares_the_kernels_of_one_key():
    """The kernels read int16 samples for every volume (``raycast._precompute.int16_samples``): float32, uint16 and
    int16 copies of one volume have one kernel key, and once one is drawn the others compile nothing."""
    vol = phantom("head", size=40)
    base = Scene(volume=vol, transfer=TransferFunction.preset("ct-bone"), shading=Shading(mode="headlight"))
    cam = Camera.orbit(vol)
    scenes = [base.with_(volume=vol.with_data(vol.data.astype(t))) for t in ("int16", "float32", "uint16")]
    assert len({kernel_key(s, cam) for s in scenes}) == 1
    render(scenes[0], cam, (16, 16))
    seen = _Compiled()
    with event.install_listener("numba:compile", seen):
        for s in scenes[1:]:
            render(s, cam, (16, 16))
    # at most the int16 copy's own small kernel, once per source type (``_precompute._shift_kernel``, if not cached)
    assert {m for m in seen.modules if m.startswith("volumen.")} <= {"volumen.render.raycast._precompute"}


def test_a_voxel_crop_box_moves_with_the_crop():
    vol = phantom("head", size=(64, 60, 56))  # (z, y, x) = (56, 60, 64): centred 48-voxel ranges start at 4, 6, 8
    nz, ny, nx = vol.shape
    scene = Scene(volume=vol, clipping=Clipping(crop=(10.0, 30.0, 0.0, ny - 1.0, 20.0, 40.0)))
    small = warm_scene(scene)
    x0, y0, z0 = ((n - WARM_EDGE) // 2 for n in (nx, ny, nz))
    assert small.clipping.crop == (10.0 - x0, 30.0 - x0, 0.0, WARM_EDGE - 1.0, 20.0 - z0, 40.0 - z0)
    assert small.volume.meta == {}
    assert kernel_key(small) == kernel_key(scene)


_COLD = textwrap.dedent('''
    from numba.core import event
    from volumen.core import Camera, Scene
    from volumen.data import phantom
    from volumen.render import default_transfer, render, warm
    from test_warm import _Compiled

    if __name__ == "__main__":
        v = phantom("head", size=(40, 40, 40))
        scene = Scene(volume=v, transfer=default_transfer(v, "mip"), mode="mip")
        cam = Camera.orbit(v)
        done = warm([(scene, cam), (scene, cam)], workers=2)
        seen = _Compiled()
        with event.install_listener("numba:compile", seen):
            render(scene, cam, (16, 16))
        print(len(done), list(done.values())[0] is not None, sum(m.startswith("volumen.") for m in seen.modules))
''')


def test_a_cold_cache_filled_by_a_child_is_read_here(tmp_path):
    """In a fresh process with an empty cache: two jobs of one kernel warm once, in a child; this process then
    compiles none of volumen's functions to draw the picture."""
    script = tmp_path / "cold.py"
    script.write_text(_COLD)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba"), PYTHONPATH=str(Path(__file__).parent))
    out = subprocess.run([sys.executable, str(script)], env=env, capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.split() == ["1", "True", "0"]
