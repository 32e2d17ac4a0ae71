"""The one thread driver of every compiled pass: one compiled function run on every Numba thread, no parallel loop.

A ``prange`` loop around a kernel compiles a second time everything the kernel inlines: Numba builds the
loop as its own function and links and optimizes the kernel's machine code into it again (about 2.5 s of a
ray-casting kernel's first use). Here a ``nogil`` kernel runs once per thread, the calling thread included,
on ``numba.get_num_threads()`` threads (what ``numba.set_num_threads`` and ``NUMBA_NUM_THREADS`` set):

* :func:`run_parts`: the kernel takes ``(part, parts, ...)`` and does the contiguous part ``part * n // parts``
  up to ``(part + 1) * n // parts`` of its items (the ray caster's ``_lightsweep``, ``_normals``,
  ``_precompute``, ``_labelled``: items of even cost). The kernel may also be a Python function whose items
  are calls of compiled ``nogil`` functions: marching cubes (``surface._mc_rows.run_pass``) hands its runs of
  rows out one at a time that way;
* :func:`run_claiming`: the kernel takes the next item with :func:`claim` (an atomic counter) whenever it
  finishes one (the tile tracer, ``render.raycast._march``: a tile's cost varies a hundredfold; static halves
  of the tiles left one thread 7% more work than the other on translucent CT, interleaved ones 1.6x), and can
  add up totals with :func:`fetch_add`.

One pool of ``NUMBA_NUM_THREADS - 1`` threads serves every pass (a forked child makes its own).
"""

from __future__ import annotations

import os
import threading
from concurrent.futures import ThreadPoolExecutor

import numba
import numpy as np
from numba import njit, types
from numba.extending import intrinsic

__all__ = ["run_parts", "run_claiming", "claim", "fetch_add"]

_pool: dict[str, ThreadPoolExecutor] = {}
_lock = threading.Lock()


def _executor() -> ThreadPoolExecutor:
    with _lock:
        if "pool" not in _pool:
            _pool["pool"] = ThreadPoolExecutor(max(numba.config.NUMBA_NUM_THREADS - 1, 1),
                                               thread_name_prefix="volumen-jit")
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


@intrinsic
def fetch_add(typingctx, counter, i, value):
    """``counter[i]``, then ``counter[i] += value``, as one atomic step (``counter``: a 1-D int64 array shared by
    the threads)."""
    if not (isinstance(counter, types.Array) and counter.dtype == types.int64 and counter.ndim == 1):
        return None

    def codegen(context, builder, signature, args):
        ary, idx, val = args
        data = context.make_array(signature.args[0])(context, builder, ary).data
        idx = context.cast(builder, idx, signature.args[1], types.intp)
        val = context.cast(builder, val, signature.args[2], types.int64)
        return builder.atomic_rmw("add", builder.gep(data, [idx]), val, "monotonic")

    return types.int64(counter, i, value), codegen


@njit(inline="always")
def claim(counter):
    """The next item of ``counter[0]``'s (``run_claiming``): a number no other call returns."""
    return fetch_add(counter, 0, 1)


def run_claiming(kernel, n: int, *args, counts: int = 0) -> np.ndarray:
    """``kernel(counter, *args)`` on ``min(threads, n)`` threads at once, the kernel taking items ``claim(counter)``
    until one is ``>= n``: a thread that finishes its items early takes more (threads that took a static part
    each waited for the slowest, 7% of a translucent CT frame's time on 2 threads). Returns ``counter[1:]``: the
    ``counts`` totals the kernel added up there (``fetch_add``)."""
    counter = np.zeros(1 + counts, np.int64)
    run_parts(_claiming, n, kernel, counter, args)
    return counter[1:]


def _claiming(part, parts, kernel, counter, args):
    kernel(counter, *args)
