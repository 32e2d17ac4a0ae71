"""The factory that turns a shared ``@njit`` function into the callable a CUDA kernel uses.

On a GPU the answer is the ``@njit`` dispatcher itself: numba's CUDA target
compiles any CPU dispatcher a kernel calls as a CUDA device function, from the
same Python source (``py_func``) and with the same options (``fastmath``,
``inline``), and does so for every function it calls in turn. So
``trace_pixel``, ``trace_path`` and the lattice sweep exist once, in
:mod:`volumen.render.raycast`, for both targets. The pieces chosen by tag (``raycast._pieces``) are
overloads: numba-cuda types them through its own registry, where ``raycast.for_cuda`` registers them
when the kernels are imported. What that source may use is
therefore limited to what both targets compile: scalars, tuples, array
indexing, ``math`` functions, builtin ``min``/``max``/``abs``/``int``, numpy
scalar casts -- no allocation, no exceptions, no numpy ufuncs on scalars
(numba's CUDA target has no lowering for ``np.sqrt`` and friends; ``math``
has the same LLVM intrinsics on the CPU).

Numba's CUDA simulator runs a kernel's Python code in Python threads and
hands it its arrays wrapped in fake device arrays, which a CPU dispatcher
cannot take: :func:`device_function` then returns a wrapper that unwraps
them and calls the dispatcher (compiled for the CPU, same source; with
``NUMBA_DISABLE_JIT=1``, as the suite runs it, the Python function itself). The
simulator thus checks everything the CUDA path adds -- grids, thread-to-pixel
maps, uploads, device caches, the per-ray sweep -- and the kernels' CUDA
compilation is checked by compiling them to PTX where a CUDA compiler exists
(``tests/render/test_cuda_backend.py``, which runs ``tests/render/cuda_ptx_check.py``).
"""

from __future__ import annotations

from ._device import simulator

__all__ = ["device_function"]


def _unwrap(a):
    if isinstance(a, tuple):  # the frame's records (NamedTuples of arrays and scalars), tags, plain tuples
        items = [_unwrap(x) for x in a]
        return type(a)(*items) if hasattr(a, "_fields") else tuple(items)
    item = getattr(a, "_item", None)  # simulator: FakeWithinKernelCUDAArray -> FakeCUDAArray -> ndarray
    if item is not None and hasattr(item, "_ary"):
        return item._ary
    ary = getattr(a, "_ary", None)
    return a if ary is None else ary


def device_function(fn):
    """The callable a ``@cuda.jit`` kernel calls for the shared ``@njit`` function ``fn``."""
    if not simulator():
        return fn

    def call(*args):
        return fn(*[_unwrap(a) for a in args])

    call.__name__ = getattr(fn, "__name__", "shared")
    call.__doc__ = fn.__doc__
    return call
