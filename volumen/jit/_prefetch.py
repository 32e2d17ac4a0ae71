"""A prefetch hint for compiled loops: ``prefetch(arr, index)`` asks the CPU to start bringing the cache line of
``arr[index]`` in, and goes on at once (``llvm.prefetch``: no fault, no result, no change to any value).

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


def prefetch(arr, index):
    """Hint that ``arr[index]`` (an integer, or a tuple of one per dimension; inside the array) will be read soon;
    nothing in Python."""


def _dims(index):
    """How many indices ``index``'s type holds (an integer, or a tuple of integers), or None."""
    if isinstance(index, types.Integer):
        return 1
    if isinstance(index, types.BaseTuple) and all(isinstance(t, types.Integer) for t in index.types):
        return len(index.types)
    return None


@intrinsic
def _hint(typingctx, arr, index):
    """``llvm.prefetch`` of the element's address: a read, kept in every cache level."""
    if not (isinstance(arr, types.Array) and _dims(index) == arr.ndim):
        return None

    def codegen(context, builder, signature, args):
        aryty, idxty = signature.args
        ary = context.make_array(aryty)(context, builder, args[0])
        if isinstance(idxty, types.Integer):
            inds = [context.cast(builder, args[1], idxty, types.intp)]
        else:
            inds = [context.cast(builder, builder.extract_value(args[1], d), t, types.intp)
                    for d, t in enumerate(idxty.types)]
        ptr = cgutils.get_item_pointer(context, builder, aryty, ary, inds, wraparound=False)
        byte = ir.IntType(8).as_pointer()
        i32 = ir.IntType(32)
        fn = cgutils.get_or_insert_function(builder.module, ir.FunctionType(ir.VoidType(), [byte, i32, i32, i32]),
                                            "llvm.prefetch.p0")
        builder.call(fn, [builder.bitcast(ptr, byte), i32(0), i32(3), i32(1)])  # read, keep, data cache
        return context.get_dummy_value()

    return types.none(arr, index), codegen


@overload(prefetch, target="cpu")
def _prefetch_cpu(arr, index):
    if isinstance(arr, types.Array) and _dims(index) == arr.ndim:
        return lambda arr, index: _hint(arr, index)
    return None


def _nothing(arr, index):
    return lambda arr, index: None


def register_cuda(cuda_overload) -> None:
    """Register ``prefetch`` with numba-cuda's ``overload``: a GPU kernel compiles it to nothing."""
    cuda_overload(prefetch)(_nothing)
