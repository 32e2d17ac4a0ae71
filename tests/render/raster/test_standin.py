"""OpenGL's stand-in while a CPU kernel compiles aside (``volumen.render._standin``): which pictures get one, the
markers that spare a later session the stand-in, the stand-in against the CPU's picture, the compile in a child
process whose cache entry the viewer then loads (a fresh process on an empty cache), the viewers' frames in
order, and a script without a main guard that is not run twice by the child."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

from volumen.core import Camera, Light, Scene, Shading
from volumen.data import phantom
from volumen.render import _ready, _standin, default_transfer, render, render_reduced
from volumen.render._ready import note_ready
from volumen.render._warm import kernel_key

#: the OpenGL ray caster against the CPU's, per picture (tests/render/raster/test_raster_raycast.py)
MEAN_TOL = 0.01
#: seconds for a child to load a kernel from the cache (or compile it, on a cold cache)
CHILD_S = 180.0


@pytest.fixture
def stand_ins(monkeypatch, tmp_path):
    """Stand-ins on (the suite turns them off), an empty record of ready kernels and no markers, as in a fresh
    process on a cache no earlier session marked."""
    monkeypatch.setenv(_standin.ENV, "1")
    monkeypatch.setattr(_ready, "_READY", set())
    monkeypatch.setattr(_ready, "marker_dir", lambda: tmp_path / "markers")
    monkeypatch.setattr(_standin, "_children", {})
    yield
    _children_end()  # a child still ending would note its kernel ready in the next test's fresh record


def _children_end():
    """Wait for every stand-in's child (and the thread that waits for it) to end, as they would on their own."""
    deadline = time.monotonic() + CHILD_S
    while any(t.name == "volumen-standin" for t in threading.enumerate()) and time.monotonic() < deadline:
        time.sleep(0.1)


@pytest.fixture(scope="module")
def head():
    return phantom("head", size=40)


def _scene(vol, mode="composite", shading="headlight") -> Scene:
    return Scene(volume=vol, transfer=default_transfer(vol, mode), mode=mode, shading=Shading(mode=shading))


def _forget():
    """No kernel noted ready in this process, and no marker."""
    _ready._READY.clear()
    for m in _ready.marker_dir().glob("*"):
        m.unlink()


def _compiled(scene, camera):
    """The scene's kernel in this process and in the disk cache (drawn once on the CPU), then forgotten as
    ready, markers too: a cache filled by something that left no marker."""
    render(scene, camera, (16, 16), device="cpu")
    _forget()


def test_which_pictures_get_a_stand_in(gl, head, stand_ins, monkeypatch):
    scene, cam = _scene(head), Camera.orbit(head)
    note_ready(kernel_key(scene, cam))
    assert _standin.compiling(scene, cam) is None  # drawn here before: the CPU draws at once
    _forget()
    other = _scene(head, shading="pathtrace")
    assert _standin.compiling(other, cam) is None  # OpenGL does not path trace
    lights = tuple(Light(kind="point", position=(0.0, 0.0, 300.0 + i)) for i in range(17))
    many = Scene(volume=head, transfer=default_transfer(head, "composite"), shading=Shading(mode="phong"),
                 lights=lights)
    assert _standin.compiling(many, cam) is None  # more lights than OpenGL's one pass takes
    assert _standin.compiling(scene, cam, device="gl") is None  # not the CPU's picture
    assert _standin.compiling(scene, cam, technique="slicing") is None
    monkeypatch.setenv(_standin.ENV, "0")
    assert _standin.compiling(scene, cam) is None  # turned off
    assert not _standin._children  # none of these started a compile


def test_a_marker_spares_a_later_session_the_stand_in(head, stand_ins):
    scene, cam = _scene(head, "mip", "none"), Camera.orbit(head)
    key = kernel_key(scene, cam)
    assert not _ready.is_ready(key)
    render(scene, cam, (16, 16), device="cpu")  # render() notes the kernel it drew, with a marker
    assert len(list(_ready.marker_dir().glob("*"))) == 1
    _ready._READY.clear()  # a new process: only the marker is left
    assert _ready.is_ready(key)
    assert _ready.is_ready(kernel_key(_scene(head, "minip", "none"), cam))  # the projections share one kernel
    assert not _ready.is_ready(kernel_key(_scene(head, "composite", "none"), cam))  # another kernel's is not


def test_stand_in_until_the_child_has_compiled_then_the_cpu(gl, head, stand_ins):
    scene, cam = _scene(head, "mip", "none"), Camera.orbit(head)
    _compiled(scene, cam)
    done = _standin.compiling(scene, cam)
    assert isinstance(done, threading.Event)
    assert _standin.compiling(scene, cam) is done  # one child per kernel
    assert done.wait(CHILD_S)
    assert _standin.compiling(scene, cam) is None and _ready.is_ready(kernel_key(scene, cam))


def test_a_stand_in_ends_when_another_warm_up_compiled_the_kernel_first(gl, head, stand_ins):
    scene, cam = _scene(head, "minip", "none"), Camera.orbit(head)
    _compiled(scene, cam)
    done = _standin.compiling(scene, cam)
    assert isinstance(done, threading.Event) and not done.is_set()
    note_ready(kernel_key(scene, cam))  # what the app's warm-up does when its child has cached this kernel
    assert done.is_set()  # the viewer draws on the CPU now, not when the stand-in's own child ends


@pytest.mark.parametrize(("mode", "shading"), [("composite", "headlight"), ("mip", "none")])
def test_the_stand_in_is_the_cpu_picture_drawn_by_opengl(gl, head, mode, shading):
    scene, cam = _scene(head, mode, shading), Camera.orbit(head, azimuth=30, elevation=15)
    size = (96, 96)
    aside = _standin.draw(scene, cam, size, 1.0)
    cpu = render_reduced(scene, cam, size, _standin.FRACTION, device="cpu")
    assert aside.stats["stand_in"] and aside.stats["reduced"]["fraction"] == _standin.FRACTION
    assert aside.rgba.shape == cpu.rgba.shape
    assert cpu.rgba[..., 3].mean() > 0.05
    diff = float(np.abs(aside.rgba - cpu.rgba).mean())
    print(f"{mode}/{shading}: stand-in vs CPU at half size, mean |RGBA diff| {diff:.4f} (<= {MEAN_TOL})")
    assert diff <= MEAN_TOL


def test_the_notebook_view_shows_the_stand_in_then_the_cpu_picture(gl, head, stand_ins):
    from volumen.notebook import View, draw_frame

    scene, cam = _scene(head), Camera.orbit(head)
    _compiled(scene, cam)
    frames = []
    view = View(scene, cam, (64, 64), on_frame=lambda f, final: frames.append((f, final)))
    try:
        assert view.wait(CHILD_S)
        assert [final for _, final in frames] == [False, True]  # OpenGL's first, then the CPU's, final
        assert np.array_equal(frames[-1][0], draw_frame(view.state))
        assert _standin.compiling(scene, cam) is None
    finally:
        view.close()


def test_a_newer_request_during_the_compile_is_the_one_drawn(gl, head, stand_ins):
    from volumen.notebook import View, draw_frame

    scene, cam = _scene(head, "mip", "none"), Camera.orbit(head)
    _compiled(scene, cam)
    frames = []
    view = View(scene, cam, (48, 48), on_frame=lambda f, final: frames.append((f, final)))
    try:
        turned = Camera.orbit(head, azimuth=90)
        view.camera = turned
        assert view.wait(CHILD_S)
        assert view.frame_state.camera == turned and frames[-1][1]
        assert np.array_equal(frames[-1][0], draw_frame(view.state))
    finally:
        view.close()


def test_the_app_worker_emits_the_stand_in_then_the_cpu_frame(gl, head, stand_ins, qtbot):
    pytest.importorskip("PySide6.QtCore", reason="the app's worker needs PySide6 (extra 'gui')")
    from volumen.app._view_picture import FrameJob
    from volumen.app._worker import RenderWorker

    scene, cam = _scene(head), Camera.orbit(head)
    _compiled(scene, cam)
    worker = RenderWorker()
    frames = []
    worker.frame_ready.connect(frames.append)
    worker.start()
    try:
        worker.submit(FrameJob(scene=scene, camera=cam, size=(64, 64), token=1))
        qtbot.waitUntil(lambda: any(f.final for f in frames), timeout=int(CHILD_S * 1000))
        assert frames[0].stats.get("stand_in") and not frames[0].final and frames[0].fraction == _standin.FRACTION
        assert frames[-1].final and not frames[-1].stats.get("stand_in")
        assert frames[-1].stats["renderer"]["device"] == "cpu"
    finally:
        worker.stop()


#: a fresh process on an empty cache opens the notebook's viewer with stand-ins on: its first frame, whether
#: OpenGL drew it, and the main kernel's cache hits and misses in this process (it must load the child's)
_FRESH = r"""
import json, sys
from volumen.core import Camera, Scene, Shading
from volumen.data import phantom
from volumen.notebook import View
from volumen.render import default_transfer
v = phantom("head", size=40)
scene = Scene(volume=v, transfer=default_transfer(v, "mip"), mode="mip", shading=Shading(mode="none"))
frames = []
view = View(scene, Camera.orbit(v), (48, 48), on_frame=lambda f, final: frames.append(final))
assert view.wait(float(sys.argv[1]))
view.close()
from volumen.render.raycast._march import _trace_tiles
print(json.dumps({"finals": frames, "hits": sum(_trace_tiles.stats.cache_hits.values()),
                  "misses": sum(_trace_tiles.stats.cache_misses.values())}))
"""


def test_a_fresh_process_loads_the_kernel_its_child_compiled(gl, tmp_path):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"), **{_standin.ENV: "1"})
    out = subprocess.run([sys.executable, "-c", _FRESH, str(CHILD_S)], env=env, capture_output=True, text=True,
                         timeout=CHILD_S + 60, check=True)
    got = json.loads(out.stdout.strip().splitlines()[-1])
    print(got)
    assert got["finals"] == [False, True]  # OpenGL's frame, then the CPU's
    assert got["hits"] == 1 and got["misses"] == 0  # the CPU's kernel came from the child's cache entry
    assert len(list((tmp_path / "cache" / "volumen").glob("*/ready/*"))) == 1  # and is marked for later


def test_a_script_without_a_main_guard_is_not_run_again_by_the_child(tmp_path, head):
    scene, cam = _scene(head, "mip", "none"), Camera.orbit(head)
    render(scene, cam, (16, 16), device="cpu")  # in the cache: the child only loads it
    runs = tmp_path / "runs.txt"
    script = tmp_path / "script.py"
    script.write_text(
        "from pathlib import Path\n"
        f"runs = Path({str(runs)!r})\n"
        "runs.write_text(runs.read_text() + 'x' if runs.exists() else 'x')\n"
        "from volumen.core import Camera, Scene, Shading\n"
        "from volumen.data import phantom\n"
        "from volumen.render import default_transfer, warm\n"
        "v = phantom('head', size=40)\n"
        "s = Scene(volume=v, transfer=default_transfer(v, 'mip'), mode='mip', shading=Shading(mode='none'))\n"
        "done = warm([(s, Camera.orbit(v))], workers=1)\n"
        "assert list(done.values())[0] is not None, done\n")
    t0 = time.perf_counter()
    subprocess.run([sys.executable, str(script)], check=True, timeout=CHILD_S)
    print(f"script with a warm-up child: {time.perf_counter() - t0:.1f} s")
    assert runs.read_text() == "x"  # the child did not run the script's body again
