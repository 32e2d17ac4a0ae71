"""Compile the kernels of several pictures side by side, in child processes, into Numba's disk cache.

A ray-casting kernel compiles for about 10-37 s on its first use on 2 cores (one per mode and shading model:
docs/design.md section 9), and a process compiles one kernel at a time (Numba's compiler lock). :func:`warm`
draws a small version of each scene (:func:`warm_scene`) in child processes, one per core, so their kernels
compile at the same time and land in the disk cache; the pictures this process draws next load them. The
cache's index files are written by one process at a time (``volumen.jit._savelock``). ``volumen demo`` warms its
gallery so; the app warms other modes and shading models in the background after its first picture.

The children are daemon processes that die with this one (``PR_SET_PDEATHSIG`` on Linux; a daemon child is
also stopped when this process exits normally), so a warm-up never outlives the program that asked for it.
Only the CPU device is warmed (the Numba kernels of ``device="cpu"``); a child that fails costs nothing but
time: the picture then compiles its kernel as it would have.
"""

from __future__ import annotations

import multiprocessing as mp
import os
import queue
import sys
import threading
import time
from collections.abc import Callable, Sequence
from contextlib import contextmanager
from dataclasses import replace

from ..core import adaptive_on
from ._ready import note_ready

__all__ = ["warm", "warm_scene", "kernel_key", "cores", "COMMON_KERNELS", "WARM_EDGE", "WARM_SIZE"]

#: (mode, shading model) of the common ray-casting kernels: what the app warms in the background and
#: ``volumen bench compile`` times (not path tracing, label maps or pre-integration)
COMMON_KERNELS = (("mip", "none"), ("minip", "none"), ("average", "none"), ("composite", "none"),
                  ("composite", "headlight"), ("composite", "phong"), ("composite", "shadows"),
                  ("composite", "scattering"), ("isosurface", "headlight"), ("isosurface", "shadows"))
#: the picture a child draws (pixels): the kernel is what it is for, not the picture
WARM_SIZE = (16, 16)
#: a volume with more voxels than this along an axis is cropped to this many about its centre for a child
WARM_EDGE = 48
#: the shading models in the order their kernels take longest to compile (longest first)
_COST = {"scattering": 0, "shadows": 1, "phong": 2, "headlight": 3, "none": 4}


def cores() -> int:
    """The cores this process may run on (its affinity, where the system tells it)."""
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def warm_scene(scene):
    """A scene whose picture needs the same kernels as ``scene``'s: the volume cropped to at most
    :data:`WARM_EDGE` voxels per axis about its centre (world positions kept, so the camera and lights still
    frame it; a voxel crop box moved with it; no metadata), unless a label map is on its grid."""
    vol = scene.volume
    if scene.labels is not None or max(vol.shape) <= WARM_EDGE:
        return scene
    ranges = [((n - min(n, WARM_EDGE)) // 2, (n - min(n, WARM_EDGE)) // 2 + min(n, WARM_EDGE)) for n in vol.shape]
    small = vol.crop(*ranges)
    small.meta.clear()
    clip = scene.clipping
    if clip.crop is not None and clip.crop_space == "voxel":
        (z0, z1), (y0, y1), (x0, x1) = ranges
        box = []
        for lo, hi, a, b in zip(clip.crop[::2], clip.crop[1::2], (x0, y0, z0), (x1, y1, z1), strict=True):
            box += [min(max(lo - a, 0.0), b - a - 1.0), min(max(hi - a, 0.0), b - a - 1.0)]
        clip = replace(clip, crop=tuple(box))
    return replace(scene, volume=small, clipping=clip)


def kernel_key(scene, camera=None) -> tuple:
    """What decides the kernels a picture compiles, as far as :func:`warm` tells jobs apart (two jobs with one
    key are warmed once). Not the volume's sample type: the kernels read int16 samples for every volume
    (``raycast._precompute.int16_samples``), so a CT, an MRI and a float volume share them."""
    from .raycast._pieces import PROJECTIONS

    sm, vol = scene.sampling, scene.volume
    mode = "projection" if scene.mode in PROJECTIONS else scene.mode  # one kernel for the three (_project)
    return (mode, scene.shading.mode, vol.is_color, scene.labels is not None,
            sm.preintegrate, sm.interpolation, sm.lattice, adaptive_on(scene), getattr(camera, "projection", None))


#: held while children start (:func:`_main_unseen`): two warm-ups at once (the app's and a stand-in's) hide and
#: restore the main script's file one after the other
_STARTING = threading.Lock()


@contextmanager
def _main_unseen():
    """While children start: hide the file of a main script that was run by path. A spawned child runs such a
    script again (as ``__mp_main__``) before its first job, and a script without an ``if __name__ ==
    "__main__"`` guard would do all its work twice (a viewer's stand-in starts a warm-up the script never asked
    for: ``volumen.render._standin``). The children draw volumen's own objects and need nothing from it. Held
    under :data:`_STARTING`; the file is gone for the milliseconds the children take to start, which a thread of
    the script reading ``__file__`` then would notice. A script run as a module (``python -m``) is imported by
    name, as multiprocessing does, and is left alone."""
    with _STARTING:
        main = sys.modules.get("__main__")
        path = getattr(main, "__file__", None)
        if path is None or getattr(main, "__spec__", None) is not None:
            yield
            return
        del main.__file__
        try:
            yield
        finally:
            main.__file__ = path


def _dies_with_parent(nice: int) -> None:
    """A child's first act: ask Linux to stop it when its parent dies (``PR_SET_PDEATHSIG``), and lower its
    priority by ``nice``."""
    try:
        import ctypes
        import signal

        ctypes.CDLL(None, use_errno=True).prctl(1, int(signal.SIGTERM))  # 1: PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass
    if nice:
        os.nice(nice)


def _serve(jobs, results) -> None:
    """Draw ``(index, scene, camera)`` jobs until the None that ends them; each result to ``results``."""
    from volumen.render import render

    while (job := jobs.get()) is not None:
        i, scene, camera = job
        t0 = time.perf_counter()
        try:
            render(scene, camera, WARM_SIZE, device="cpu")
            results.put((i, time.perf_counter() - t0, None))
        except Exception as exc:  # noqa: BLE001 - reported; the picture compiles its kernel itself then
            results.put((i, None, f"{type(exc).__name__}: {exc}"))


def _child(jobs, results, parent: int, nice: int, kernels: str | None = None) -> None:
    """A warming process: :func:`_serve` once it is sure to die with its parent, its kernels in ``kernels`` (the
    parent's kernel folder, whatever the environment it inherited says now)."""
    if kernels:
        os.environ["VOLUMEN_KERNEL_DIR"] = kernels
    _dies_with_parent(nice)
    if os.getppid() == parent:  # else the parent died before the request above
        _serve(jobs, results)


def _kernels() -> str | None:
    """This process's kernel folder, where it has fixed one (``volumen.jit.kernel_folder``), for its children."""
    jit = sys.modules.get("volumen.jit")
    return str(jit.kernel_folder()) if jit is not None else None


def _order(jobs):
    """One job per :func:`kernel_key`, the slowest to compile first (the children take them in this order)."""
    seen: dict = {}
    for scene, camera in jobs:
        seen.setdefault(kernel_key(scene, camera), (scene, camera))
    return sorted(seen.items(), key=lambda kv: (_COST.get(kv[0][1], 5), kv[0][0] != "composite"))


def warm(jobs: Sequence, workers: int | None = None, progress: Callable[[str], None] | None = None, *,
         nice: int = 0, cancel: threading.Event | None = None, here: bool = False) -> dict:
    """Compile the kernels that drawing each ``(scene, camera)`` of ``jobs`` needs, ``workers`` processes at a
    time (default: one per core, at most one per distinct kernel).

    ``here``: this process is one of them (it takes jobs too, after starting ``workers - 1`` children, and keeps
    their kernels in memory): for a command that waits for the warm-up anyway (``volumen demo``). Otherwise
    every job runs in a child, as a background warm-up needs (``nice`` and ``cancel`` apply to children only).

    Returns ``{kernel_key: seconds}``: each distinct key's draw in its child (compiling, or loading from the
    cache), None where it failed. ``progress``, when given, gets one line per finished key. ``nice``: the
    children's added niceness (a background warm-up yields to the pictures being drawn). ``cancel``: once set,
    the children are stopped and the keys not finished are left out (a kernel half compiled is not cached).
    """
    todo = _order(jobs)
    done: dict = {}
    if not todo or (cancel is not None and cancel.is_set()):
        return done
    workers = max(1, min(workers or cores(), len(todo)))
    ctx = mp.get_context("spawn")
    inbox, results = ctx.Queue(), ctx.Queue()
    for i, (_, (scene, camera)) in enumerate(todo):
        inbox.put((i, warm_scene(scene), camera))
    for _ in range(workers):
        inbox.put(None)
    procs = [ctx.Process(target=_child, args=(inbox, results, os.getpid(), nice, _kernels()), daemon=True,
                         name=f"volumen-warm-{n}") for n in range(workers - 1 if here else workers)]
    with _main_unseen():
        for p in procs:
            p.start()
    try:
        if here:
            _serve(inbox, results)
        while len(done) < len(todo) and not (cancel is not None and cancel.is_set()):
            alive = any(p.is_alive() for p in procs)  # asked before reading: a child's last result is sent
            try:                                        # before it ends
                i, seconds, error = results.get(timeout=0.25)
            except queue.Empty:
                if not alive:
                    break  # every child ended (one crashed): what is left compiles when drawn
                continue
            key = todo[i][0]
            done[key] = seconds
            if error is None:
                note_ready(key)
            if progress:
                said = f"{seconds:.1f} s" if error is None else f"failed to warm: {error}"
                progress(f"  kernel {len(done)}/{len(todo)} ({key[0]}, {key[1]}): {said}")
    finally:
        for p in procs:
            if p.is_alive():
                p.terminate()
        for p in procs:
            p.join(5)
        inbox.cancel_join_thread()  # jobs no child took are dropped, not flushed at exit
    return done
