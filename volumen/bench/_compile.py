"""``volumen bench compile``: how long the first picture of each ray-casting mode takes in a fresh process.

Each case runs in a child process with its own empty Numba cache (``NUMBA_CACHE_DIR``): the time from the
``render`` call to the picture is the cold compile of that (mode, shading model)'s kernel, plus the per-volume
tables, on a 48^3 head phantom at 64x64 (the picture itself takes milliseconds). A second child with the same
cache then shows the cached start. Imports are timed apart. A third child, with an empty cache of its own, opens
the notebook's viewer (``volumen.notebook.View``, whose render loop the desktop app's worker mirrors) on the same
scene at 384x384: ``shown`` is the time to its first frame (OpenGL's stand-in while the kernel compiles aside,
``volumen.render._standin``), ``viewer CPU`` to its CPU-drawn final frame. Cases run one after another, so the machine's
other load is the only noise; the bar is :data:`BAR_S` per mode. Without
``--quick`` a last row times what ``make demo`` runs after installing, ``volumen demo``, from an empty cache and
again from the cache it filled (its gallery's kernels compile side by side, ``volumen.render.warm``; bar
:data:`DEMO_BAR_S`).
"""

from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
import tempfile
import time

from volumen.render._warm import COMMON_KERNELS

from ._table import Table

__all__ = ["bench_compile", "CASES"]

#: (mode, shading) of each first picture
CASES = COMMON_KERNELS
QUICK = (("mip", "none"),)
#: a mode's first picture from a cold cache, seconds: the bar
BAR_S = 5.0
#: ``make demo`` from a cold cache after installation, seconds: the bar
DEMO_BAR_S = 40.0

#: the scene every child draws: the head phantom at 48^3 in the (mode, shading) of its arguments
_SCENE = r"""
import json, sys, time
t0 = time.perf_counter()
from volumen.core import Camera, Light, Scene, Shading
from volumen.data import phantom
from volumen.render import default_transfer, render
from volumen.notebook import View
t1 = time.perf_counter()
mode, shading = sys.argv[1], sys.argv[2]
v = phantom("head", size=(48, 48, 48))
lights = (Light(kind="point", position=tuple(v.center + [0, 0, 200])),) if shading in ("shadows", "scattering") else ()
scene = Scene(volume=v, transfer=default_transfer(v, mode), mode=mode, shading=Shading(mode=shading), lights=lights)
"""
#: the scene's first picture through ``render``
_CHILD = _SCENE + r"""
c0, w0 = time.process_time(), time.perf_counter()
image = render(scene, Camera.orbit(v), (64, 64))
print(json.dumps({"imports": t1 - t0, "wall": time.perf_counter() - w0, "cpu": time.process_time() - c0,
                  "max": float(image.rgba[..., :3].max())}))
"""
#: the same scene in the notebook's viewer: seconds to its first frame and to its final (CPU) frame
_VIEWER = _SCENE + r"""
seen = []
w0 = time.perf_counter()
view = View(scene, Camera.orbit(v), (384, 384), on_frame=lambda f, final: seen.append((time.perf_counter(), final)))
assert view.wait(600), "no final frame"
view.close()
print(json.dumps({"shown": seen[0][0] - w0, "cpu": [t for t, final in seen if final][0] - w0,
                  "stand_in": not seen[0][1]}))
"""


def _cold_env(cache: str) -> dict:
    """This process's environment with ``cache`` as the kernel folder (``NUMBA_CACHE_DIR``; an exported
    ``VOLUMEN_KERNEL_DIR``, which would win, is dropped)."""
    env = dict(os.environ, NUMBA_CACHE_DIR=cache)
    env.pop("VOLUMEN_KERNEL_DIR", None)
    return env


def _child(script: str, mode: str, shading: str, cache: str) -> dict:
    env = _cold_env(cache)
    out = subprocess.run([sys.executable, "-c", script, mode, shading], env=env, capture_output=True, text=True,
                         check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def _demo(cache: str) -> dict:
    """``volumen demo`` in a child process with ``cache`` as its Numba cache: wall and CPU seconds (children's)."""
    env = _cold_env(cache)
    cpu0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    with tempfile.TemporaryDirectory(prefix="volumen-demo-") as out:
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-m", "volumen", "demo", "--out", out], env=env, capture_output=True,
                       check=True)
        wall = time.perf_counter() - t0
    cpu1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    return {"wall": wall, "cpu": (cpu1.ru_utime + cpu1.ru_stime) - (cpu0.ru_utime + cpu0.ru_stime)}


def bench_compile(quick: bool = False) -> Table:
    """Cold and cached first-picture seconds per (mode, shading); returns the table."""
    table = Table("First picture in a fresh process: cold Numba cache, then cached (48^3 phantom, 64x64)",
                  [("mode", "mode", ""), ("shading", "shading", ""), ("cold_s", "cold s", ".1f"),
                   ("cold_cpu_s", "cold CPU s", ".1f"), ("cached_s", "cached s", ".2f"),
                   ("imports_s", "imports s", ".1f"), ("bar", f"<= {BAR_S:.0f} s", ""),
                   ("shown_s", "viewer shown s", ".1f"), ("viewer_cpu_s", "viewer CPU s", ".1f"),
                   ("shown_bar", f"shown <= {BAR_S:.0f} s", "")])
    for mode, shading in QUICK if quick else CASES:
        with tempfile.TemporaryDirectory(prefix="volumen-numba-") as cache:
            cold = _child(_CHILD, mode, shading, cache)
            warm = _child(_CHILD, mode, shading, cache)
        with tempfile.TemporaryDirectory(prefix="volumen-numba-") as cache:
            viewer = _child(_VIEWER, mode, shading, cache)
        table.add(mode=mode, shading=shading, cold_s=cold["wall"], cold_cpu_s=cold["cpu"], cached_s=warm["wall"],
                  imports_s=cold["imports"], bar="yes" if cold["wall"] <= BAR_S else "NO",
                  shown_s=viewer["shown"], viewer_cpu_s=viewer["cpu"],
                  shown_bar=("yes" if viewer["shown"] <= BAR_S else "NO") + ("" if viewer["stand_in"] else
                                                                               " (no stand-in)"))
    table.notes.append("cold: the render call in a child process with an empty NUMBA_CACHE_DIR (kernel compile "
                       "and per-volume tables); cached: a second child with that cache; imports timed apart")
    table.notes.append("viewer: the notebook's View on the same scene at 384x384 in a child with an empty cache "
                       "of its own; shown: its first frame (OpenGL's stand-in at half size while the kernel "
                       "compiles in a grandchild), CPU: its final frame drawn by the CPU ray caster")
    if not quick:
        with tempfile.TemporaryDirectory(prefix="volumen-numba-") as cache:
            cold, warm = _demo(cache), _demo(cache)
        table.add(mode="volumen demo", shading="gallery", cold_s=cold["wall"], cold_cpu_s=cold["cpu"],
                  cached_s=warm["wall"], imports_s=None,
                  bar=f"{'yes' if cold['wall'] <= DEMO_BAR_S else 'NO'} (<= {DEMO_BAR_S:.0f} s)")
        table.notes.append(f"volumen demo: the whole command (phantoms, slices, 18 gallery pictures), its kernels "
                           f"compiled in one process per core ({os.cpu_count()}); cold CPU s: all its processes")
    return table
