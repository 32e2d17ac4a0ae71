"""The CPU kernels' threads: one compiled function run on every Numba thread, without a Numba parallel loop.

A ``prange`` loop around a kernel compiles a second time everything the kernel inlines: Numba builds the
loop as its own function and links and optimizes the kernel's machine code into it again (about 2.5 s of a
ray-casting kernel's first use). Here the kernel (``nogil``, from ``_march`` and ``_lightsweep``) takes
``(first, stride, ...)`` and does items ``first, first + stride, ...`` of its work; :func:`run_strided`
calls it once per thread, the calling thread included, on ``numba.get_num_threads()`` threads (what
``numba.set_num_threads`` and ``NUMBA_NUM_THREADS`` set). Interleaved items (tiles in raster order, lattice
rows) balance the threads as well as the loop's chunks did.
"""

from __future__ import annotations

import os
import threading
from concurrent.futures import ThreadPoolExecutor

import numba

__all__ = ["run_strided"]

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


def run_strided(kernel, n: int, *args) -> None:
    """``kernel(first, stride, *args)`` for ``first`` in ``0 .. stride - 1``, ``stride = min(threads, n)``, in
    parallel; returns when all are done (an exception in any is raised here)."""
    stride = max(min(numba.get_num_threads(), n), 1)
    if stride == 1:
        kernel(0, 1, *args)
        return
    futures = [_executor().submit(kernel, first, stride, *args) for first in range(1, stride)]
    try:
        kernel(0, stride, *args)
    finally:
        for f in futures:
            f.result()
