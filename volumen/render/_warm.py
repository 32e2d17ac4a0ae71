"""Compile the kernels of several pictures side by side, in child processes, into Numba's disk cache.

A ray-casting kernel compiles for about 8-20 s on its first use (one per mode and shading model: docs/design.md
section 9), and a process compiles one kernel at a time (Numba's compiler lock). :func:`warm` draws a small
version of each scene (:func:`warm_scene`) in child processes, one per core, so their kernels compile at the
same time and land in the disk cache; the pictures this process draws next load them from there. The cache's
index files are written by one process at a time (``volumen.jit._savelock``). ``volumen demo`` warms its gallery
so; the app warms the other shading models in the background after its first picture.

Only the CPU device is warmed (the Numba kernels of ``device="cpu"``); a child that fails costs nothing but
time: the picture then compiles its kernel as it would have.
"""

from __future__ import annotations

import multiprocessing as mp
import os
import threading
import time
from collections.abc import Callable, Sequence
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from dataclasses import replace

__all__ = ["warm", "warm_scene", "kernel_key", "WARM_EDGE", "WARM_SIZE"]

#: the picture a child draws (pixels): the kernel is what it is for, not the picture
WARM_SIZE = (16, 16)
#: a volume with more voxels than this along an axis is cropped to this many about its centre for a child
WARM_EDGE = 48
#: the shading models and modes in the order their kernels take longest to compile (longest first)
_COST = {"scattering": 0, "shadows": 1, "phong": 2, "headlight": 3, "none": 4}


def warm_scene(scene):
    """A scene whose picture needs the same kernels as ``scene``'s: the volume cropped to at most
    :data:`WARM_EDGE` voxels per axis about its centre (the same type, so the same compiled signatures; world
    positions kept, so the camera and lights still frame it), unless a label map is on its grid."""
    vol = scene.volume
    if scene.labels is not None or max(vol.shape) <= WARM_EDGE:
        return scene
    ranges = [((n - min(n, WARM_EDGE)) // 2, (n - min(n, WARM_EDGE)) // 2 + min(n, WARM_EDGE)) for n in vol.shape]
    return replace(scene, volume=vol.crop(*ranges))


def kernel_key(scene) -> tuple:
    """What decides the kernels a scene's picture compiles, as far as :func:`warm` tells scenes apart (two scenes
    with one key are warmed once)."""
    sm, vol = scene.sampling, scene.volume
    return (scene.mode, scene.shading.mode, str(vol.dtype), vol.is_color, scene.labels is not None,
            sm.preintegrate, sm.interpolation, sm.lattice, sm.adaptive)


def _draw(scene, camera) -> float:
    from volumen.render import render

    t0 = time.perf_counter()
    render(scene, camera, WARM_SIZE, device="cpu")
    return time.perf_counter() - t0


def _order(jobs):
    """One job per :func:`kernel_key`, the slowest to compile first (a pool then balances them)."""
    seen: dict = {}
    for scene, camera in jobs:
        seen.setdefault(kernel_key(scene), (scene, camera))
    return sorted(seen.items(), key=lambda kv: (_COST.get(kv[0][1], 5), kv[0][0] != "composite"))


def warm(jobs: Sequence, workers: int | None = None, progress: Callable[[str], None] | None = None, *,
         nice: int = 0, cancel: threading.Event | None = None) -> dict:
    """Compile the kernels that drawing each ``(scene, camera)`` of ``jobs`` needs, ``workers`` child processes
    at a time (default: one per core).

    Returns ``{kernel_key: seconds}``: each distinct key's draw in its child (compiling, or loading from the
    cache), None where the child failed. ``progress``, when given, gets one line per finished key. ``nice``:
    the children's added niceness (a background warm-up yields to the pictures being drawn). ``cancel``: once
    set, the children are stopped and the keys not finished are left out (a kernel half compiled is not
    cached; the cache's files are replaced whole).
    """
    todo = _order(jobs)
    done: dict = {}
    if not todo:
        return done
    workers = max(1, min(workers or os.cpu_count() or 1, len(todo)))
    pool = ProcessPoolExecutor(max_workers=workers, mp_context=mp.get_context("spawn"),
                               initializer=os.nice if nice else None, initargs=(nice,) if nice else ())
    futures = {pool.submit(_draw, warm_scene(scene), camera): key for key, (scene, camera) in todo}
    pending = set(futures)
    try:
        while pending and not (cancel is not None and cancel.is_set()):
            finished, pending = wait(pending, timeout=0.25, return_when=FIRST_COMPLETED)
            for fut in finished:
                done[futures[fut]] = _result(fut, len(done) + 1, len(todo), futures[fut], progress)
    finally:
        if pending:
            for proc in list(getattr(pool, "_processes", {}).values()):  # no public way to stop a running child
                proc.terminate()
        pool.shutdown(wait=not pending, cancel_futures=True)
    return done


def _result(fut, n, total, key, progress):
    """A finished child's seconds (None where it failed), said to ``progress``."""
    try:
        seconds = fut.result()
    except Exception as exc:  # noqa: BLE001 - the picture compiles its kernel itself then
        if progress:
            progress(f"  kernel {n}/{total} ({key[0]}, {key[1]}) failed to warm: {exc}")
        return None
    if progress:
        progress(f"  kernel {n}/{total} ({key[0]}, {key[1]}): {seconds:.1f} s")
    return seconds
