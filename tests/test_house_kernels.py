"""House rules for compiled code, over all of ``volumen/``, by reading the source (no import, no compile).

* a compiled function takes at most 8 parameters -- compiled: decorated by Numba (``njit``, ``jit``,
  ``cuda.jit``, ``overload``, ``intrinsic``, ``generated_jit``, ``vectorize``, ``cfunc``, ``stencil``), by a
  name bound to such a decorator (``row_kernel = njit(...)``), registered as a piece's implementation
  (``@step.register(...)``, ``raycast._pieces``), compiled by a call (``njit(...)(f)``,
  ``device_function(f)``), or a piece made by ``piece(name, "params")`` (its tag counts);
* kernel state is read by name: no subscript of a state variable (``st``, ``state``) by an integer constant
  (``st[3]``) or a constant slice (``st[:5]``) in a compiled function;
* a packed array is read through the named constants declared next to its packer: no integer constant as the
  index of ``cam``, ``geo``, ``whole``, ``meta`` (``cam[14]``), nor as the column of the per-row tables
  ``lights``, ``light_meta``, ``planes`` (``lights[i, 9]``).

Each rule is shown to fail on a planted example (a small source string given to the checker) and to pass on
the tree.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import volumen

ROOT = Path(volumen.__file__).parent
MAX_PARAMS = 8
#: what Numba compiles a function with, as a decorator or a call's callee
COMPILERS = {"njit", "jit", "overload", "intrinsic", "generated_jit", "vectorize", "guvectorize", "cfunc", "stencil",
             "device_function"}
#: names of kernel state (the marching loop's per-mode state, ``raycast._pieces``)
STATE = {"st", "state"}
#: packed 1-D arrays (``raycast._geometry.pack_camera``, ``pack_geometry``; a light's meta row, ``_params``)
PACKED = {"cam", "geo", "whole", "meta"}
#: packed tables of one row per item, read by column (``_shade.pack_lights``, ``_lightvol``, ``pack_planes``)
PACKED_ROWS = {"lights", "light_meta", "planes"}


def _callee(node) -> str:
    """The last name of a decorator or callee: ``njit`` of ``numba.njit(cache=True)``, ``jit`` of ``cuda.jit``."""
    while isinstance(node, ast.Call):
        node = node.func
    if isinstance(node, ast.Attribute):
        return node.attr
    return node.id if isinstance(node, ast.Name) else ""


def _int(node) -> bool:
    return isinstance(node, ast.Constant) and type(node.value) is int


def _constant_index(node) -> bool:
    """An integer constant, or a slice whose given bounds are integer constants (``[:5]``, ``[12:15]``)."""
    if isinstance(node, ast.Slice):
        bounds = [b for b in (node.lower, node.upper) if b is not None]
        return bool(bounds) and all(_int(b) for b in bounds)
    return _int(node)


def _name(node) -> str:
    if isinstance(node, ast.Attribute):
        return node.attr
    return node.id if isinstance(node, ast.Name) else ""


def _params(fn) -> int:
    a = fn.args
    return len(a.posonlyargs) + len(a.args) + len(a.kwonlyargs) + (a.vararg is not None) + (a.kwarg is not None)


def check(source: str, where: str = "<source>") -> list[str]:
    """The problems of one module's source, as ``where:line: what``."""
    tree = ast.parse(source)
    compilers = set(COMPILERS)
    compiled_by_call = set()
    problems = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Assign) and isinstance(node.value, ast.Call) and _callee(node.value) in COMPILERS:
            compilers |= {t.id for t in node.targets if isinstance(t, ast.Name)}  # row_kernel = njit(...)
    for node in ast.walk(tree):
        if isinstance(node, ast.Call) and _callee(node) in compilers:
            compiled_by_call |= {a.id for a in node.args if isinstance(a, ast.Name)}  # njit(...)(f)
        if isinstance(node, ast.Call) and _callee(node) == "piece" and len(node.args) >= 2 \
                and isinstance(node.args[1], ast.Constant) and isinstance(node.args[1].value, str):
            n = 1 + len([p for p in node.args[1].value.split(",") if p.strip()])
            if n > MAX_PARAMS:
                problems.append(f"{where}:{node.lineno}: piece {ast.literal_eval(node.args[0])!r} takes {n} parameters")
    in_kernels = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            decorated = any(_callee(d) in compilers or _callee(d) == "register" for d in node.decorator_list)
            if decorated or node.name in compiled_by_call:
                in_kernels |= {id(n) for n in ast.walk(node)}
                if _params(node) > MAX_PARAMS:
                    problems.append(f"{where}:{node.lineno}: compiled {node.name} takes {_params(node)} parameters")
    for node in ast.walk(tree):
        if isinstance(node, ast.Subscript):
            name, index = _name(node.value), node.slice
            if name in STATE and _constant_index(index):
                if id(node) in in_kernels:
                    problems.append(f"{where}:{node.lineno}: positional read of kernel state {ast.unparse(node)}")
            elif name in PACKED and _constant_index(index):
                problems.append(f"{where}:{node.lineno}: magic index into packed {ast.unparse(node)}")
            elif name in PACKED_ROWS and isinstance(index, ast.Tuple) and len(index.elts) == 2 \
                    and _constant_index(index.elts[1]):
                problems.append(f"{where}:{node.lineno}: magic column of packed {ast.unparse(node)}")
    return problems


def _tree_problems() -> list[str]:
    out = []
    for path in sorted(ROOT.rglob("*.py")):
        out += check(path.read_text(encoding="utf-8"), str(path.relative_to(ROOT.parent)))
    return out


PLANTED = {
    "parameters": '''
from numba import njit

@njit(cache=True)
def kernel(a, b, c, d, e, f, g, h, i):
    return a
''',
    "parameters through a bound decorator": '''
from numba import njit
row_kernel = njit(nogil=True)

@row_kernel
def kernel(a, b, c, d, e, f, g, h, i):
    return a
''',
    "parameters through a call": '''
from numba import njit

def kernel(a, b, c, d, e, f, g, h, i):
    return a

compiled = njit(cache=True)(kernel)
''',
    "parameters of a piece's implementation": '''
@step.register(Composite)
def _step(light, r, a, s, st, k, t, v, have, span):
    return st
''',
    "parameters of a piece": '''
step = piece("step", "light, r, a, s, st, k, t, v, have, span")
''',
    "state read by position": '''
from numba import njit

@njit
def finish(st, out):
    out[0] = st[3]
''',
    "state sliced by position": '''
@step.register(Preintegrated)
@njit(cache=True, fastmath=True, inline="always")
def _step_pre(light, r, a, s, st, smp):
    return st[:5] + (smp.v, smp.t), 0, False
''',
    "magic index into the camera": '''
def key(a, px, py):
    return py * int(a.cam[14]) + px
''',
    "magic slice of the region": '''
def box(geo):
    return geo[12:15]
''',
    "magic column of the lights": '''
def spot(a, li):
    return a.lights[li, 9]
''',
}


@pytest.mark.parametrize("rule", list(PLANTED))
def test_the_checker_finds_a_planted_example(rule):
    problems = check(PLANTED[rule], rule)
    print(problems)
    assert len(problems) == 1, problems


def test_named_reads_and_small_kernels_pass():
    """The same code written by the rules: no problem; and a variable called ``st`` outside compiled code (plane
    coordinates, say) is not kernel state."""
    good = '''
from numba import njit
from ._geometry import C_W, G_BOX

@njit(cache=True)
def kernel(a, s, ray, span, key, ctr):
    st = init(a)
    return st.alpha, a.cam[C_W], a.geo[G_BOX:G_BOX + 3], a.lights[ray, L_EXP], ray[0]

step = piece("step", "light, r, a, s, st, smp")

def corners(plane, pts):
    st, _ = plane.to_plane(pts)
    return st[0], st[2]
'''
    assert check(good) == []


def test_the_tree_keeps_the_rules():
    problems = _tree_problems()
    print(f"{len(problems)} problems in {ROOT}")
    assert not problems, "\n".join(problems)
