"""Numba's IR inliner without its repeated work: three narrow patches that cut the kernels' cold compile 1.5-3x.

The marching skeleton reaches every per-sample function through ``inline="always"`` (``_march``) and the mode
and light pieces through inlined overloads (``_pieces``): one flat kernel per (mode, light), which is what makes
it fast. Numba repeats work while building it. Each patch replaces one private internal of Numba, names the
upstream report it works around and what would let it go:

* **Copying a callee's IR, block by block** (``numba.core.inline_closurecall.copy``, read by
  ``InlineWorker.inline_ir``'s ``copy_ir``, whose local ``the_ir`` the copier reads from the caller's frame).
  Each block is deep-copied with a fresh memo, so every block copies the callee's whole ``Scope`` (all its
  variables) again: the cost grows as blocks x variables. :class:`_BlockCopier` shares one memo across the
  blocks of one copy, which is what one deep copy of the whole IR would do: each block still gets its own
  statements, and all of them one new scope (as in the original, where the blocks share one scope).
  Upstream: numba/numba#8989 (open), NVIDIA/numba-cuda#688 (open); goes when ``copy_ir`` copies the IR once.
* **Typing an inlined overload again for the same argument types**
  (``numba.core.typing.templates._OverloadFunctionTemplate.generic``). Type inference revisits a call to an
  ``inline="always"`` overload and re-runs the implementation's untyped passes and type inference each time (88
  times for 8 distinct signatures in the composite-headlight kernel). :func:`_cached_generic` keeps the answer
  per (template, typing context, argument types); the template records the inlining information on its first
  call, keyed the same way. Upstream: NVIDIA/numba-cuda#914 (open: memoizes overload resolution per typing
  context and argument types); goes when Numba does that.
* **Compiling an inlined overload's implementation on its own** (``numba.core.dispatcher.Dispatcher.
  get_call_template`` and its ``_can_compile`` flag). Numba compiles it to machine code that is never used (it
  is inlined), linking and optimizing again everything it calls. Implementations marked :func:`inline_only` (the
  pieces of ``_pieces``) are typed but not compiled (:func:`_typing_only`). Upstream: numba/numba#6856 ("Avoid
  recompiling inlined overload impl", closed unmerged); goes when Numba skips that compile.

numba-cuda (0.30) carries its own copy of these three internals (``numba.cuda.core.inline_closurecall``,
``numba.cuda.typing.templates``, ``numba.cuda.dispatcher.CUDADispatcher``), through which the CUDA kernels compile:
:func:`install_cuda` patches them alike when the kernels are first imported (``_pieces.for_cuda``), inside
``NUMBA_CUDA_TESTED``. Its ``copy_ir`` copies the blocks in a dict comprehension, so the copier looks for
``the_ir`` one frame further up there. The composite-with-shadows kernel then compiled to PTX in 38 s instead of
217 s on 2 cores, the four kernels of ``tests/render/cuda_ptx_check.py`` in 108 s instead of 325 s, to the same PTX.

None changes what is compiled: pictures are bit-identical with and without them (``tests/render/test_inlining.py``
compiles one kernel both ways in fresh processes). :func:`install` (run on import, before any kernel compiles)
patches only inside the tested Numba range (:mod:`volumen.jit._guard`: ``pyproject.toml``'s range; outside it,
or with ``VOLUMEN_NUMBA_PATCHES=0``, the patches stand down and a warning says so once) and only when Numba has
the code the patches expect.
"""

from __future__ import annotations

import copy
import sys

from ._guard import cuda_patches_allowed, patches_allowed

__all__ = ["install", "install_cuda", "active", "inline_only"]

_state = {"installed": False, "cuda": False}


class _BlockCopier:
    """``copy`` as ``inline_closurecall`` sees it, whose ``deepcopy`` of an ``ir.Block`` from its IR copy
    (``copy_ir``: the ``FunctionIR`` being copied is its local ``the_ir``) shares one memo with the other blocks
    of the same copy. A block seen again, or another IR, starts a new copy; without ``the_ir`` (another Numba)
    every block is copied on its own, as Numba's own ``copy`` does."""

    def __init__(self, block_type):
        self._block_type = block_type
        self._ir = None
        self._seen: set[int] = set()
        self._memo: dict = {}
        self.copy = copy.copy
        self.Error = copy.Error

    def deepcopy(self, x, memo=None):
        if memo is not None or type(x) is not self._block_type:
            return copy.deepcopy(x, memo)
        caller = sys._getframe(1)
        the_ir = caller.f_locals.get("the_ir")
        if the_ir is None and caller.f_code.co_name == "<dictcomp>":  # numba-cuda's copy_ir: its own frame < 3.12
            the_ir = caller.f_back.f_locals.get("the_ir")
        if the_ir is None:
            return copy.deepcopy(x)
        if the_ir is not self._ir or id(x) in self._seen:
            self._ir, self._seen, self._memo = the_ir, set(), {}
        self._seen.add(id(x))
        return copy.deepcopy(x, self._memo)


def inline_only(fn):
    """Mark the Python implementation ``fn`` of an ``inline="always"`` overload (``_pieces``): its dispatcher is
    typed but never compiled on its own. Numba compiles it once per signature anyway (to check that it can, and
    to surface ``literally`` requests, which these implementations do not make); that machine code is never
    used, and compiling it links and optimizes again everything the implementation calls."""
    setattr(fn, _MARK, True)
    return fn


_MARK = "_volumen_inline_only"


def _typing_only(original):
    def get_call_template(self, args, kws):
        if not (getattr(self.py_func, _MARK, False) and self._can_compile):
            return original(self, args, kws)
        self._can_compile = False
        try:
            return original(self, args, kws)
        finally:
            self._can_compile = True

    get_call_template.__wrapped__ = original
    return get_call_template


def _cached_generic(original):
    cache: dict = {}

    def generic(self, args, kws):
        key = (type(self), id(self.context), tuple(args), tuple(sorted(kws.items())) if kws else ())
        try:
            hash(key)
        except TypeError:
            return original(self, args, kws)
        if key not in cache:
            cache[key] = original(self, args, kws)
        return cache[key]

    generic.__wrapped__ = original
    return generic


def _patch(inline_closurecall, block_type, tpl, disp) -> bool:
    """The three patches on one copy of Numba's compiler (its inliner module, its ``ir.Block``, its overload
    template, its dispatcher class), where it has the code they expect; whether they were applied."""
    if (getattr(inline_closurecall, "copy", None) is not copy or not hasattr(tpl, "generic")
            or not hasattr(disp, "get_call_template")):
        return False
    inline_closurecall.copy = _BlockCopier(block_type)
    tpl.generic = _cached_generic(tpl.generic)
    disp.get_call_template = _typing_only(disp.get_call_template)
    return True


def install() -> bool:
    """Apply the three patches once (process-wide) where :func:`volumen.jit.patches_allowed`; whether they are in
    place."""
    if _state["installed"]:
        return True
    if not patches_allowed():
        return False
    from numba.core import dispatcher, inline_closurecall, ir
    from numba.core.typing import templates

    _state["installed"] = _patch(inline_closurecall, ir.Block, getattr(templates, "_OverloadFunctionTemplate", None),
                                 dispatcher.Dispatcher)
    return _state["installed"]


def install_cuda() -> bool:
    """The same three patches in numba-cuda's own copy of the compiler (``numba.cuda.core.inline_closurecall``,
    ``numba.cuda.typing.templates``, ``CUDADispatcher``), through which the CUDA kernels compile (``for_cuda``
    calls it), where :func:`volumen.jit.cuda_patches_allowed`; whether they are in place."""
    if _state["cuda"]:
        return True
    if not cuda_patches_allowed():
        return False
    from numba.cuda import dispatcher
    from numba.cuda.core import inline_closurecall, ir
    from numba.cuda.typing import templates

    _state["cuda"] = _patch(inline_closurecall, ir.Block, getattr(templates, "_OverloadFunctionTemplate", None),
                            dispatcher.CUDADispatcher)
    return _state["cuda"]


def active() -> bool:
    """Whether :func:`install` has patched Numba in this process."""
    return _state["installed"]


install()
