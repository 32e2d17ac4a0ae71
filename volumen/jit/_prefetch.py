"""A prefetch hint for compiled loops: ``prefetch(arr, k, j, i)`` asks the CPU to start bringing the cache line
of ``arr[k, j, i]`` in, and goes on at once (``llvm.prefetch``: no fault, no result, no change to any value).

A ray caster's samples read the volume and its normal codes at places no hardware prefetcher can guess (the
ray's direction is arbitrary), and each read waits for memory: on a whole-abdomen CT (366 x 303 x 336 int16, 74
MB of samples and 74 MB of codes) a Phong frame spent most of a sample's time waiting. Asking for the lines of a
sample a few steps ahead lets those waits overlap the work of the samples in between (``raycast._march``).

``prefetch`` is a Python function that does nothing (``NUMBA_DISABLE_JIT=1``); compiled for the CPU it is the
hint; on the GPU (numba-cuda, which types kernels through its own registry: :func:`register_cuda`) nothing.
"""

from __future__ import annotations

from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic, overload

__all__ = ["prefetch", "register_cuda"]


def prefetch(arr, k, j, i):
    """Hint that ``arr[k, j, i]`` (a 3-D array; indices inside it) will be read soon; nothing in Python."""


@intrinsic
def _hint(typingctx, arr, k, j, i):
    """``llvm.prefetch`` of the element's address: a read, kept in every cache level."""
    if not (isinstance(arr, types.Array) and arr.ndim == 3):
        return None

    def codegen(context, builder, signature, args):
        aryty = signature.args[0]
        ary = context.make_array(aryty)(context, builder, args[0])
        inds = [context.cast(builder, v, t, types.intp) for v, t in zip(args[1:], signature.args[1:], strict=True)]
        ptr = cgutils.get_item_pointer(context, builder, aryty, ary, inds, wraparound=False)
        byte = ir.IntType(8).as_pointer()
        i32 = ir.IntType(32)
        fn = cgutils.get_or_insert_function(builder.module, ir.FunctionType(ir.VoidType(), [byte, i32, i32, i32]),
                                            "llvm.prefetch.p0")
        builder.call(fn, [builder.bitcast(ptr, byte), i32(0), i32(3), i32(1)])  # read, keep, data cache
        return context.get_dummy_value()

    return types.none(arr, k, j, i), codegen


@overload(prefetch, target="cpu")
def _prefetch_cpu(arr, k, j, i):
    if isinstance(arr, types.Array) and arr.ndim == 3:
        return lambda arr, k, j, i: _hint(arr, k, j, i)
    return None


def _nothing(arr, k, j, i):
    return lambda arr, k, j, i: None


def register_cuda(cuda_overload) -> None:
    """Register ``prefetch`` with numba-cuda's ``overload``: a GPU kernel compiles it to nothing."""
    cuda_overload(prefetch)(_nothing)
