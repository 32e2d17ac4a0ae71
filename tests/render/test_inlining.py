"""The two fixes to Numba's IR inliner (``raycast._inlining``) and the threads that replaced the parallel loops.

The fixes make the kernels' cold compile about 2-5x shorter (``volumen bench compile``); these tests check what
they promise: that they are in place with the installed Numba, that an IR copy is still a deep copy whose
blocks share one new scope, that an inlined overload is typed but never compiled on its own, and that
``run_parts`` and ``run_claiming`` visit every item once on every thread count.
"""

from __future__ import annotations

import contextlib

import numpy as np
import pytest
from numba import njit
from numba.core import event, ir
from numba.core.compiler import run_frontend

from volumen.render.raycast import inlining_active
from volumen.render.raycast._inlining import _BlockCopier
from volumen.render.raycast._pieces import piece
from volumen.render.raycast._threads import claim, fetch_add, run_claiming, run_parts


def test_fixes_are_in_place_with_this_numba():
    assert inlining_active()


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


def test_ir_copy_is_deep_and_its_blocks_share_one_new_scope():
    the_ir = run_frontend(_branchy)
    assert len(the_ir.blocks) > 3
    copier = _BlockCopier(ir.Block)
    first = _copy_blocks(the_ir, copier)
    scopes = {id(b.scope) for b in first.values()}
    assert len(scopes) == 1 and id(the_ir.blocks[min(the_ir.blocks)].scope) not in scopes
    for label, block in first.items():
        orig = the_ir.blocks[label]
        assert block is not orig and len(block.body) == len(orig.body)
        assert all(a is not b and str(a) == str(b) for a, b in zip(block.body, orig.body, strict=True))
    second = _copy_blocks(the_ir, copier)  # the same IR copied again: a new copy, sharing nothing with the first
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
