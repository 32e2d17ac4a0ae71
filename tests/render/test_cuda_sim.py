"""The ``cuda`` device on numba's CUDA simulator gives the CPU's pixels, for every mode and shading model.

The simulator must be switched on before numba loads, and this test process
must stay out of it (the other tests run compiled CPU code), so one
subprocess (``cuda_scenes.py`` with ``NUMBA_ENABLE_CUDASIM=1``) renders
every scene of :func:`cuda_scenes.scenes` with ``device="cuda"`` -- the
kernels, the device caches, the illumination volumes swept on the device,
the path tracer's device accumulation -- and the CPU renders them here.
Tolerance: 1e-4 on rgba, depth and projected values (the issue's CI bound;
1e-3 is the acceptance bound).

The subprocess also sets ``NUMBA_DISABLE_JIT=1``: the shared ``@njit``
functions the kernels call run as their Python source -- the source numba-cuda
compiles for a GPU -- rather than compiled for the CPU one (mode, light)
variant at a time (12 standalone compiles of ``trace_pixel`` and the path
tracer: about 840 s of one core on a cold cache, against 18 s this way). So
the comparison is between two executions of one source, Python's and the CPU
kernels'; they agree to float32 rounding (at most 2e-7 here). The kernels'
CUDA compilation is checked by compiling them to PTX (test_cuda_backend).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tests.render import cuda_scenes
from volumen.render import render

HERE = Path(__file__).parent
TOL = 1e-4


@pytest.fixture(scope="module")
def simulated(tmp_path_factory):
    out = tmp_path_factory.mktemp("cuda_sim") / "sim.npz"
    env = dict(os.environ, NUMBA_ENABLE_CUDASIM="1", NUMBA_DISABLE_JIT="1")
    env["PYTHONPATH"] = os.pathsep.join([str(HERE), env.get("PYTHONPATH", "")])
    r = subprocess.run([sys.executable, str(HERE / "cuda_scenes.py"), str(out)], env=env, cwd=HERE,
                       capture_output=True, text=True, timeout=1800)  # the simulator runs kernels in Python
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-4000:]
    return dict(np.load(out))


def _close(a, b, what):
    a = np.asarray(a, np.float64)
    b = np.asarray(b, np.float64)
    same_special = (np.isinf(a) & np.isinf(b)) | (np.isnan(a) & np.isnan(b))
    assert np.array_equal(np.isfinite(a), np.isfinite(b)), what
    d = np.abs(np.where(same_special, 0.0, a) - np.where(same_special, 0.0, b))
    print(f"{what}: max |cpu - cuda| = {d.max():.3g}")
    assert d.max() <= TOL, (what, d.max())


@pytest.mark.parametrize("name", list(cuda_scenes.scenes()))
def test_cuda_pixels_equal_cpu_pixels(name, simulated):
    scene, cam, size = cuda_scenes.scenes()[name]
    cpu = render(scene, cam, size, device="cpu")
    assert cpu.rgba[..., 3].max() > 0.2  # the scene shows something
    _close(cpu.rgba, simulated[f"{name}/rgba"], f"{name} rgba")
    _close(cpu.depth, simulated[f"{name}/depth"], f"{name} depth")
    if cpu.value is not None:
        _close(cpu.value, simulated[f"{name}/value"], f"{name} value")
    if "fast" in name or name == "isosurface-shadows":  # the illumination volume was swept on the device
        assert int(simulated[f"{name}/built"]) >= 1


def test_outputs_follow_the_picture_size(simulated):
    """The device's outputs, kept between frames of one size, are made anew when the size changes: each frame
    of a size change and back equals the CPU's."""
    for label, scene, cam, size in cuda_scenes.resized_sequence():
        cpu = render(scene, cam, size, device="cpu")
        assert simulated[f"resized/{label}/rgba"].shape == (size[1], size[0], 4)
        _close(cpu.rgba, simulated[f"resized/{label}/rgba"], f"resized {label} rgba")
        _close(cpu.depth, simulated[f"resized/{label}/depth"], f"resized {label} depth")


def test_lit_models_differ_so_the_comparison_means_something(simulated):
    """Every lighting model changes the picture: equal pixels are not equal by accident of a dark scene."""
    names = ["composite-none", "composite-phong", "shadows-direct", "scattering-direct", "pathtrace"]
    rgb = [simulated[f"{n}/rgba"][..., :3] for n in names]
    for i in range(len(rgb)):
        for j in range(i + 1, len(rgb)):
            assert np.abs(rgb[i] - rgb[j]).max() > 0.02, (names[i], names[j])


def test_device_cache_uploads_only_what_changed(simulated):
    log = {label: (set(up), built) for label, up, built in json.loads(str(simulated["uploads"]))}
    first, built = log["first"]
    assert {"vol", "lut", "extinction", "cam", "lights"} <= first and built == 1  # settings go by value, not uploaded
    # the same frame again sweeps nothing and sends only the transparent cells, built from a transfer function's
    # second frame on (``raycast._cells``)
    assert log["same"] == ({"cells"}, 0)
    assert log["camera"] == ({"cam"}, 0)  # world-fixed lights: their illumination volume is kept
    up, built = log["transfer"]
    assert {"lut", "extinction"} <= up and built == 1  # new tables, the light volume swept again
    assert not up & {"vol", "gradient_matrix", "bmin", "bmax"}  # the volume stays on the device
    assert log["light-intensity"] == ({"lights", "cells"}, 0)  # intensity is not in the illumination volume (the
    # cells of the new transfer function: its second frame)
