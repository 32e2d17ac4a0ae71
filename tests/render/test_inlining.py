"""The three patches to Numba's inliner (``jit._inlining``; numba-cuda's copy of it too), their fences, and the
one thread driver.

The patches make the kernels' cold compile shorter (``volumen bench compile``: about 1.5x on MIP, more on the
lit composite kernels); these tests check what they promise: that they are in place with the installed Numba
(inside the tested range that ``pyproject.toml`` states) and stand down outside it, that a kernel built from
the ray caster's pieces compiles to the same results with and without them and in less time, that an IR copy
is still a deep copy whose blocks share one new scope, that an inlined overload is typed but never compiled on
its own, and that ``run_parts`` and ``run_claiming`` visit every item once on every thread count.
"""

from __future__ import annotations

import contextlib
import copy
import re
from pathlib import Path

import numba
import numpy as np
import pytest
from numba import njit
from numba.core import event, ir
from numba.core.compiler import run_frontend

from volumen.jit import ENV, NUMBA_TESTED, claim, fetch_add, in_tested_range, patches_allowed, run_claiming, run_parts
from volumen.jit._inlining import _BlockCopier
from volumen.render.raycast import inlining_active
from volumen.render.raycast._pieces import piece

ROOT = Path(__file__).resolve().parents[2]


def test_fixes_are_in_place_with_this_numba():
    assert in_tested_range(), f"Numba {numba.__version__} is outside NUMBA_TESTED {NUMBA_TESTED}"
    assert inlining_active()


def test_pyproject_states_the_tested_numba_range():
    """The requirement users install against is the range the guard lets the patches apply in."""
    import tomllib

    deps = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]["dependencies"]
    (numba_req,) = [d for d in deps if d.startswith("numba")]
    first, end = (".".join(map(str, v)) for v in NUMBA_TESTED)
    assert numba_req.replace(" ", "") == f"numba>={first},<{end}"


def test_outside_the_tested_range_the_patches_stand_down_and_say_so_once(monkeypatch):
    from volumen.jit import _guard

    monkeypatch.setattr(_guard, "numba_version", lambda: (NUMBA_TESTED[1][0], NUMBA_TESTED[1][1], 0))
    monkeypatch.setattr(_guard, "_warned", set())
    with pytest.warns(RuntimeWarning, match="outside the range") as caught:
        assert not patches_allowed() and not patches_allowed()
    assert len(caught) == 1
    monkeypatch.setattr(_guard, "numba_version", lambda: (0, 60, 1))
    assert not in_tested_range()
    monkeypatch.setenv(ENV, "0")
    monkeypatch.setattr(_guard, "numba_version", lambda: NUMBA_TESTED[0] + (0,))
    assert not patches_allowed()



def test_outside_its_tested_range_the_cuda_patches_stand_down_and_say_so_once(monkeypatch):
    """numba-cuda's copy of the compiler is patched (``_inlining.install_cuda``) only in ``NUMBA_CUDA_TESTED``."""
    import numba_cuda

    from volumen.jit import NUMBA_CUDA_TESTED, _guard, cuda_patches_allowed

    monkeypatch.setattr(_guard, "_warned", set())
    monkeypatch.setattr(numba_cuda, "__version__", ".".join(map(str, NUMBA_CUDA_TESTED[0])) + ".4")
    assert cuda_patches_allowed()
    monkeypatch.setattr(numba_cuda, "__version__", ".".join(map(str, NUMBA_CUDA_TESTED[1])) + ".0")
    with pytest.warns(RuntimeWarning, match="numba-cuda .* outside the range") as caught:
        assert not cuda_patches_allowed() and not cuda_patches_allowed()
    assert len(caught) == 1
    monkeypatch.setattr(numba_cuda, "__version__", ".".join(map(str, NUMBA_CUDA_TESTED[0])) + ".4")
    monkeypatch.setenv(ENV, "0")
    assert not cuda_patches_allowed()


def test_numba_cuda_internals_the_patches_replace_have_the_shape_they_expect():
    """The same three internals in numba-cuda's copy of the compiler, which the CUDA kernels compile through (the
    PTX check, ``test_cuda_backend.py``, compiles them patched and one unpatched, to the same PTX)."""
    import inspect

    from numba.cuda import dispatcher
    from numba.cuda.core import inline_closurecall
    from numba.cuda.typing import templates

    copy_ir = next(c for c in inline_closurecall.InlineWorker.inline_ir.__code__.co_consts
                   if getattr(c, "co_name", "") == "copy_ir")
    nested = [copy_ir, *(c for c in copy_ir.co_consts if hasattr(c, "co_names"))]
    assert "the_ir" in copy_ir.co_varnames and any({"copy", "deepcopy"} <= set(c.co_names) for c in nested)
    assert inline_closurecall.copy is copy or isinstance(inline_closurecall.copy, _BlockCopier)
    gct = dispatcher.CUDADispatcher.get_call_template
    assert list(inspect.signature(getattr(gct, "__wrapped__", gct)).parameters) == ["self", "args", "kws"]
    assert "_can_compile" in getattr(gct, "__wrapped__", gct).__code__.co_names
    generic = templates._OverloadFunctionTemplate.generic
    assert list(inspect.signature(getattr(generic, "__wrapped__", generic)).parameters) == ["self", "args", "kws"]


def _shape_problems() -> list[str]:
    """What no longer looks as the four patches expect in the installed Numba: each the internal, the change, and
    what it costs (``jit/_inlining.py``, ``jit/_locate.py``)."""
    import inspect

    from numba.core import caching, dispatcher, inline_closurecall
    from numba.core.typing import templates

    def params(fn) -> list[str]:
        return list(inspect.signature(getattr(fn, "__wrapped__", fn)).parameters)

    out = []
    copy_ir = next((c for c in inline_closurecall.InlineWorker.inline_ir.__code__.co_consts
                    if getattr(c, "co_name", "") == "copy_ir"), None)
    if copy_ir is None or "the_ir" not in copy_ir.co_varnames or not {"copy", "deepcopy"} <= set(copy_ir.co_names):
        out.append("inline_closurecall.InlineWorker.inline_ir has no nested copy_ir(the_ir) calling copy.deepcopy: "
                   "the block copier cannot find the IR it copies (silently slower compiles, 27 s and more)")
    if not isinstance(getattr(inline_closurecall, "copy", None), _BlockCopier):
        out.append("inline_closurecall.copy is not volumen's _BlockCopier: the block-copy patch is not in place")
    tpl = getattr(templates, "_OverloadFunctionTemplate", None)
    if tpl is None or params(tpl.generic) != ["self", "args", "kws"]:
        out.append("typing.templates._OverloadFunctionTemplate.generic is not generic(self, args, kws): the "
                   "overload typing cache would call it wrongly")
    gct = dispatcher.Dispatcher.get_call_template
    gct_names = getattr(gct, "__wrapped__", gct).__code__.co_names
    if params(gct) != ["self", "args", "kws"] or "_can_compile" not in gct_names:
        out.append("dispatcher.Dispatcher.get_call_template(self, args, kws) no longer reads self._can_compile: "
                   "inline_only pieces would be compiled anyway, or every kernel break")
    elif njit(lambda x: x)._can_compile is not True:
        out.append("a new Dispatcher's _can_compile is not True: the typing-only patch would stop its compiles")
    init_names = caching.CacheImpl.__init__.__code__.co_names
    locators = getattr(caching.CacheImpl, "_locator_classes", None)
    if not isinstance(locators, list) or not {"_locator_classes", "from_function"} <= set(init_names):
        out.append("caching.CacheImpl no longer picks a locator from its _locator_classes list with from_function: "
                   "cached kernels are keyed on their own file only (a stale cache after editing a helper)")
    elif [c.__module__ for c in locators[:2]] != ["volumen.jit._locate"] * 2:
        out.append(f"the content-keyed locators are not first in CacheImpl._locator_classes: {locators[:2]}")
    elif params(caching.InTreeCacheLocator.from_function) != ["py_func", "py_file"] or \
            params(caching.InTreeCacheLocator.get_source_stamp) != ["self"] or \
            not hasattr(caching._CacheLocator, "ensure_cache_path"):
        out.append("caching.InTreeCacheLocator.from_function(py_func, py_file) / get_source_stamp(self) or "
                   "_CacheLocator.ensure_cache_path changed: the content-keyed locators cannot extend them")
    return out


def test_the_numba_internals_the_patches_replace_still_have_the_shape_they_expect():
    """Not only that the four patched internals exist: their signatures, the local the block copier reads from
    its caller's frame, the flag the typing-only patch flips, the locator list the cache walks. A Numba release
    that reshapes one fails here, saying which and what it costs, instead of silently compiling 1.5-3x slower or
    keeping a stale cache."""
    problems = _shape_problems()
    assert not problems, (f"Numba {numba.__version__} changed internals volumen patches (NUMBA_TESTED "
                          f"{NUMBA_TESTED}): fix the patch or lower pyproject.toml's numba ceiling and NUMBA_TESTED "
                          "below this release.\n  " + "\n  ".join(problems))


def test_each_patch_names_the_upstream_report_it_works_around_and_what_lets_it_go():
    from volumen.jit import _inlining
    from volumen.jit import _locate as _stamp

    patches = _inlining.__doc__.split("\n* ")[1:]
    assert len(patches) == 3
    for text in patches:
        assert re.search(r"Upstream: [\w-]+/[\w-]+#\d+", text) and "goes when" in text, text
    assert re.search(r"upstream: numba/numba#\d+", _stamp.__doc__) and "goes when" in _stamp.__doc__

def test_a_reshaped_internal_is_named_in_the_failure(monkeypatch):
    from numba.core import dispatcher

    original = dispatcher.Dispatcher.get_call_template

    def get_call_template(self, args, kws, extra=None):  # a Numba release that added a parameter
        return original(self, args, kws)

    monkeypatch.setattr(dispatcher.Dispatcher, "get_call_template", get_call_template)
    (problem,) = _shape_problems()
    assert problem.startswith("dispatcher.Dispatcher.get_call_template(self, args, kws)")


# A kernel built as the ray caster's are: pieces (inlined overloads picked by a tag), reaching branchy
# ``inline="always"`` functions, typed with the same arguments many times. Compiled in a fresh process
# with and without the patches (``VOLUMEN_NUMBA_PATCHES``); CPU seconds of the compile, compiles counted.
_AB_CHILD = r"""
import json, sys, time
from typing import NamedTuple
from numba import njit
from numba.core import event
from volumen.jit import ENV, NUMBA_TESTED, in_tested_range, patches_allowed
from volumen.render.raycast import inlining_active
from volumen.render.raycast._pieces import piece

class Tag(NamedTuple):
    pass

@njit(inline="always")
def branchy(x, n):
    acc = 0.0
    for i in range(n):
        if x > i:
            acc += x * i
        elif x < -i:
            acc -= x / (i + 1.0)
        else:
            acc += 0.5
        if acc > 100.0:
            acc = acc * 0.5
    return acc

@njit(inline="always")
def twice(x):
    return branchy(x, 3) + branchy(-x, 4)

shaded = piece("ab_shaded", "x")

@shaded.register(Tag)
@njit(inline="always")
def _shaded(x):
    return twice(x) - twice(x + 1.0)

def kernel(x):
    t = Tag()
    return shaded(t, x) + shaded(t, -x)

compiled = []

class Count(event.Listener):
    def on_start(self, ev):
        compiled.append(ev.data["dispatcher"].py_func.__name__)

    def on_end(self, ev):
        pass

fn = njit(kernel)
with event.install_listener("numba:compile", Count()):
    c0 = time.process_time()
    fn.compile("float64(float64)")
    cpu = time.process_time() - c0
print(json.dumps({"active": inlining_active(), "cpu": cpu, "compiled": compiled,
                  "values": [fn(x) for x in (-7.5, -1.0, 0.0, 0.25, 3.0, 11.0)]}))
"""


def _compile_in_a_fresh_process(patches: str) -> dict:
    import json
    import os
    import subprocess
    import sys

    env = dict(os.environ, VOLUMEN_NUMBA_PATCHES=patches, NUMBA_DISABLE_JIT="0")
    out = subprocess.run([sys.executable, "-c", _AB_CHILD], env=env, capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_a_kernel_of_pieces_compiles_the_same_and_faster_with_the_patches():
    """Same values to the last bit; the inlined piece is never compiled on its own with the patches; the compile
    takes less CPU time (``volumen bench compile`` measures the real kernels: MIP 15.4 s against 23.3 s)."""
    on, off = _compile_in_a_fresh_process("1"), _compile_in_a_fresh_process("0")
    print(f"compile CPU s: {on['cpu']:.2f} with the patches, {off['cpu']:.2f} without; "
          f"compiled {on['compiled']} with, {off['compiled']} without")
    assert on["active"] and not off["active"]
    assert on["values"] == off["values"]
    assert "impl" in off["compiled"] and "impl" not in on["compiled"]  # the piece's implementation (inline_only)
    assert on["cpu"] < off["cpu"]


def _branchy(x, n):
    acc = 0.0
    for i in range(n):
        if x > i:
            acc += x * i
        else:
            acc -= i
    return acc


def _copy_blocks(the_ir, copier):
    """What ``InlineWorker.inline_ir``'s ``copy_ir`` does with the ``copy`` it sees (the same local name)."""
    blocks = {}
    for label in the_ir.blocks:
        blocks[label] = copier.deepcopy(the_ir.blocks[label])
    return blocks


def _copy_blocks_in_a_comprehension(the_ir, copier):
    """numba-cuda's ``copy_ir``: the blocks copied in a dict comprehension (its own frame before Python 3.12)."""
    return {label: copier.deepcopy(block) for label, block in the_ir.blocks.items()}


@pytest.mark.parametrize("copy_blocks", [_copy_blocks, _copy_blocks_in_a_comprehension], ids=["numba", "numba-cuda"])
def test_ir_copy_is_deep_and_its_blocks_share_one_new_scope(copy_blocks):
    the_ir = run_frontend(_branchy)
    assert len(the_ir.blocks) > 3
    copier = _BlockCopier(ir.Block)
    first = copy_blocks(the_ir, copier)
    scopes = {id(b.scope) for b in first.values()}
    assert len(scopes) == 1 and id(the_ir.blocks[min(the_ir.blocks)].scope) not in scopes
    for label, block in first.items():
        orig = the_ir.blocks[label]
        assert block is not orig and len(block.body) == len(orig.body)
        assert all(a is not b and str(a) == str(b) for a, b in zip(block.body, orig.body, strict=True))
    second = copy_blocks(the_ir, copier)  # the same IR copied again: a new copy, sharing nothing with the first
    assert {id(b.scope) for b in second.values()}.isdisjoint(scopes)
    assert all(s.body[0] is not f.body[0] for s, f in zip(second.values(), first.values(), strict=True))




def test_inlined_piece_is_typed_but_not_compiled_on_its_own():
    from typing import NamedTuple

    class Double(NamedTuple):
        pass

    double = piece("double_for_test", "x")

    @double.register(Double)
    @njit(inline="always")
    def _double(x):
        return 2.0 * x

    @njit
    def caller(x):
        return double(Double(), x) + 1.0

    compiled = []

    class Listener(event.Listener):
        def on_start(self, ev):
            compiled.append(ev.data["dispatcher"].py_func)

        def on_end(self, ev):
            pass

    with event.install_listener("numba:compile", Listener()):
        assert caller(3.0) == pytest.approx(7.0)
    names = [f.__qualname__ for f in compiled]
    assert any("caller" in n for n in names)
    assert not any(getattr(f, "_volumen_inline_only", False) for f in compiled), names


@contextlib.contextmanager
def _threads(threads):
    """Numba's thread count set to ``threads`` (at most the configured count) inside the block."""
    import numba

    old = numba.get_num_threads()
    numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
    try:
        yield
    finally:
        numba.set_num_threads(old)


@njit(nogil=True)
def _mark(part, parts, hits):
    n = hits.shape[0]
    for i in range(part * n // parts, (part + 1) * n // parts):
        hits[i] += 1


@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("n", [1, 2, 7, 1000])
def test_run_parts_visits_every_item_once(threads, n):
    hits = np.zeros(n, np.int64)
    with _threads(threads):
        run_parts(_mark, n, hits)
    assert (hits == 1).all()


def test_run_parts_raises_a_kernel_error():
    def failing(part, parts):
        if part == 0:
            raise ValueError("bad item")

    with pytest.raises(ValueError, match="bad item"):
        run_parts(failing, 4)


@njit(nogil=True)
def _take(counter, hits, spin):
    """Items ``claim(counter)`` until past ``hits``: each marked, its number added to counter[1], a count of them
    to counter[2]; item 0 is slow (``spin`` iterations), so the other thread takes most of the rest."""
    n = claim(counter)
    while n < hits.shape[0]:
        if n == 0:
            x = 0.0
            for i in range(spin):
                x += np.sqrt(i)
            hits[n] += 1 if x >= 0.0 else 2
        else:
            hits[n] += 1
        fetch_add(counter, 1, n)
        fetch_add(counter, 2, 1)
        n = claim(counter)


@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("n", [1, 2, 7, 100_000])
def test_run_claiming_visits_every_item_once_and_adds_up(threads, n):
    hits = np.zeros(n, np.int64)
    with _threads(threads):
        total, count = run_claiming(_take, n, hits, 10_000_000, counts=2)
    assert (hits == 1).all()
    assert total == n * (n - 1) // 2
    assert count == n
