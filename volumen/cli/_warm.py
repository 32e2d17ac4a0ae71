"""``volumen warm``: compile every kernel the viewers and the command line can ask for, now, on every core.

Kernels compile on their first use and are kept in the machine's kernel cache (``volumen.jit``: one folder per
content key, shared by every checkout of the same code), so each is compiled once per machine and release. This
command does it ahead, with a progress bar, skipping what is cached.

A ray-casting kernel is decided by its mode and shading model and by a few options (``render._warm.kernel_key``).
:func:`catalogue` lists the (mode, shading) pairs the viewers offer (:data:`SHADED_MODES`), each with the default
options, and each of :data:`OPTIONS` changed on the default composite picture and on MIP: the variants a user
reaches with one flag or one menu entry. They are drawn small in child processes, one per core
(``volumen.render.warm``). The commands that compile kernels of their own (marching cubes; the endoscope's lumen,
collision and flight) run once each on a phantom, in child processes too (:data:`COMMANDS`). ``--common``: only
the kernels the application warms after its first picture (``render._warm.COMMON_KERNELS``).
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
from dataclasses import replace

import numpy as np

__all__ = ["register", "run", "catalogue", "SHADED_MODES", "OPTIONS", "COMMANDS"]

#: (mode, shading) pairs a viewer offers: the projections unshaded (mip, minip and average share one kernel),
#: composite with every model, isosurfaces lit
SHADED_MODES = (("mip", "none"),
                *(("composite", s) for s in ("none", "headlight", "phong", "shadows", "scattering", "pathtrace")),
                *(("isosurface", s) for s in ("none", "headlight", "phong", "shadows")))
#: the options changed one at a time on the default composite picture and on MIP
OPTIONS = ("nearest", "bspline", "full-rate", "preintegrate", "labels", "colour", "lattice", "orthographic")
#: the commands whose kernels are not the ray caster's, run on phantoms (``volumen ARGV``; ``{out}``: a folder)
COMMANDS = (("mesh", "phantom:head", "--iso", "300", "-o", "{out}/head.stl"),
            ("fly", "phantom:airways", "--lumen", "air", "--start", "0,1,40", "--end", "-26,-8,-14",
             "-o", "{out}/airways.gif", "--size", "16x16", "--frames", "2", "--unfold", "{out}/unfolded.png"))


def register(sub):
    p = sub.add_parser("warm", help="compile every kernel the viewers and commands use, now, on every core "
                                    "(skips what is cached)")
    p.add_argument("--common", action="store_true",
                   help="only the common ray-casting kernels (the ones the application warms after its first picture)")
    p.add_argument("--workers", type=int, default=None, help="processes at a time (default: one per core)")
    p.add_argument("--list", action="store_true", help="list the kernels and whether each is cached; compile none")
    return p


def _scene(volume, mode: str, shading: str):
    from volumen.core import Isosurface, Scene, Shading
    from volumen.render import default_transfer

    return Scene(volume=volume, mode=mode, transfer=default_transfer(volume, mode), shading=Shading(mode=shading),
                 isosurface=Isosurface(value=300.0))


def _with_option(scene, camera, option: str):
    """``(scene, camera)`` with one :data:`OPTIONS` entry changed."""
    from volumen.core import LabelLayer, LabelMap, Volume

    sm, vol = scene.sampling, scene.volume
    if option in ("nearest", "bspline"):
        return replace(scene, sampling=replace(sm, interpolation=option)), camera
    if option == "full-rate":
        return replace(scene, sampling=replace(sm, adaptive=False)), camera
    if option in ("preintegrate", "lattice"):
        return replace(scene, sampling=replace(sm, **{option: True})), camera
    if option == "labels":
        labels = LabelMap((vol.data > 300).astype(np.uint8), affine=vol.affine)
        return replace(scene, labels=LabelLayer(labels=labels)), camera
    if option == "colour":
        grey = np.clip((vol.data.astype(np.float32) + 1000) / 8, 0, 255).astype(np.uint8)
        return replace(scene, volume=Volume(np.stack([grey] * 3, axis=-1), affine=vol.affine)), camera
    return scene, replace(camera, projection="orthographic")


def catalogue(common: bool = False) -> list[tuple[str, object, object]]:
    """``[(label, scene, camera)]``: one small picture per ray-casting kernel variant (:data:`SHADED_MODES` and
    :data:`OPTIONS`; ``common``: ``COMMON_KERNELS`` only), on a 32-voxel head phantom (every volume reaches the
    kernels as int16 samples: one serves for all)."""
    from volumen.core import Camera
    from volumen.data import phantom
    from volumen.render._warm import COMMON_KERNELS

    vol = phantom("head", size=32)
    camera = Camera.orbit(vol, view="anterior")
    pairs = COMMON_KERNELS if common else SHADED_MODES
    jobs = [(f"{'mip/minip/average' if m == 'mip' else m} {s}", _scene(vol, m, s), camera) for m, s in pairs
            if m not in ("minip", "average")]
    if common:
        return jobs
    for base in (_scene(vol, "composite", "headlight"), _scene(vol, "mip", "none")):
        for option in OPTIONS:
            if option in ("preintegrate", "labels") and base.mode != "composite":
                continue
            jobs.append((f"{base.mode} {base.shading.mode}, {option}", *_with_option(base, camera, option)))
    return jobs


def _commands(out: str, workers: int, bar) -> list[str]:
    """Run :data:`COMMANDS` in child processes, ``workers`` at a time; the failures, one line each."""
    from volumen.jit import kernel_folder

    failed, running, todo = [], [], list(COMMANDS)
    env = dict(os.environ, VOLUMEN_STANDIN="0", VOLUMEN_KERNEL_DIR=str(kernel_folder()))
    while todo or running:
        while todo and len(running) < workers:
            argv = [a.format(out=out) for a in todo.pop(0)]
            running.append((argv, subprocess.Popen([sys.executable, "-m", "volumen", *argv], env=env,
                                                   stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)))
        argv, proc = running.pop(0)
        err = proc.communicate()[1]
        bar.update(1)
        if proc.returncode:
            failed.append(f"volumen {argv[0]}: " + (err.strip().splitlines() or ["failed"])[-1])
    return failed


def run(args):
    from tqdm import tqdm

    from volumen.render import warm
    from volumen.render._ready import is_ready
    from volumen.render._warm import cores, kernel_key

    jobs = catalogue(args.common)
    keys = {kernel_key(scene, camera): label for label, scene, camera in jobs}
    cached = {k for k in keys if is_ready(k)}
    if args.list:
        for key, label in keys.items():
            print(f"{'cached ' if key in cached else 'to do  '} {label}")
        if not args.common:
            print(f"and the kernels of {', '.join('volumen ' + c[0] for c in COMMANDS)}, which volumen warm runs")
        return 0
    todo = [(scene, camera) for _, scene, camera in jobs if kernel_key(scene, camera) not in cached]
    commands = 0 if args.common else len(COMMANDS)
    workers = max(1, args.workers or cores())
    print(f"{len(keys)} ray-casting kernels, {len(cached)} cached; compiling {len(todo)}"
          + (f" and running {commands} commands" if commands else "") + f", {workers} at a time", flush=True)
    t0 = time.perf_counter()
    failed = []
    with tqdm(total=len({kernel_key(*j) for j in todo}) + commands, desc="warm", unit="kernel") as bar:
        done = warm(todo, workers=workers, progress=lambda line: bar.update(1)) if todo else {}
        failed += [f"{keys[kernel_key(s, c)]}: not warmed (it compiles on first use)" for s, c in todo
                   if done.get(kernel_key(s, c)) is None]
        if commands:
            with tempfile.TemporaryDirectory(prefix="volumen-warm-") as out:
                failed += _commands(out, workers, bar)
    for line in failed:
        print(f"volumen warm: warning: {line}", file=sys.stderr)
    print(f"kernels ready in {time.perf_counter() - t0:.0f} s")
    return 0
