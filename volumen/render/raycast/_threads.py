"""The CPU kernels' threads: one compiled function run on every Numba thread, without a Numba parallel loop.

A ``prange`` loop around a kernel compiles a second time everything the kernel inlines: Numba builds the
loop as its own function and links and optimizes the kernel's machine code into it again (about 2.5 s of a
ray-casting kernel's first use). Here the kernel (``nogil``: ``_march``, ``_lightsweep``, ``_normals``,
``_precompute``) takes ``(part, parts, ...)`` and does the contiguous part ``part`` of ``parts`` of its
items, ``part * n // parts`` up to ``(part + 1) * n // parts``; :func:`run_parts` calls it once per thread,
the calling thread included, on ``numba.get_num_threads()`` threads (what ``numba.set_num_threads`` and
``NUMBA_NUM_THREADS`` set). Contiguous parts, as the parallel loop's static chunks were: the tiles' order
(``_cpu.tile_order``) spreads the picture's expensive middle over them (interleaved tiles left one thread
1.6x the other's work on the aorta).
"""

from __future__ import annotations

import os
import threading
from concurrent.futures import ThreadPoolExecutor

import numba

__all__ = ["run_parts"]

_pool: dict[str, ThreadPoolExecutor] = {}
_lock = threading.Lock()


def _executor() -> ThreadPoolExecutor:
    with _lock:
        if "pool" not in _pool:
            _pool["pool"] = ThreadPoolExecutor(max(numba.config.NUMBA_NUM_THREADS - 1, 1),
                                               thread_name_prefix="volumen-raycast")
        return _pool["pool"]


def _forget_pool() -> None:
    """In a forked child: the parent's pool threads do not exist there, so it gets its own pool."""
    global _lock
    _lock = threading.Lock()
    _pool.clear()


os.register_at_fork(after_in_child=_forget_pool)


def run_parts(kernel, n: int, *args) -> None:
    """``kernel(part, parts, *args)`` for ``part`` in ``0 .. parts - 1``, ``parts = min(threads, n)``, in
    parallel; returns when all are done (an exception in any is raised here)."""
    parts = max(min(numba.get_num_threads(), n), 1)
    if parts == 1:
        kernel(0, 1, *args)
        return
    futures = [_executor().submit(kernel, part, parts, *args) for part in range(1, parts)]
    try:
        kernel(0, parts, *args)
    finally:
        for f in futures:
            f.result()
