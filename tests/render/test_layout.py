"""Code-shape rules for ``volumen/render``, and the frame records reaching both targets.

* no function over 80 lines (its ``def`` to its last line, docstring included);
* no kernel with more than 8 parameters -- kernels being the compiled entry
  points a driver launches: ``@cuda.jit`` kernels, ``parallel=True`` drivers,
  and the per-pixel functions they call (``trace_pixel``, ``trace_path``);
* the per-frame arrays and settings are declared once (``raycast._frame``):
  every field of ``Arrays`` goes to the device (``Frame.device_arrays``), and a
  setting is a named field with its default that kernels read by name.
"""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np

import volumen.render

ROOT = Path(volumen.render.__file__).parent
MAX_LINES = 80
MAX_KERNEL_PARAMS = 8
PER_PIXEL = {"trace_pixel", "trace_path"}


def _functions():
    for path in sorted(ROOT.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                yield path.relative_to(ROOT.parent.parent), node


def _is_kernel(node) -> bool:
    if node.name in PER_PIXEL:
        return True
    for d in node.decorator_list:
        src = ast.unparse(d)
        if src.startswith("cuda.jit") or "parallel=True" in src:
            return True
    return False


def test_no_function_over_80_lines():
    """Every function of every package of ``volumen/render`` (ray caster, CUDA, raster, API)."""
    functions = list(_functions())
    lengths = sorted(((n.end_lineno - n.lineno + 1, f"{p}:{n.name}") for p, n in functions), reverse=True)
    print("longest in volumen/render:", lengths[:3])
    packages = {p.parts[2] for p, _ in functions}
    assert {"raycast", "cuda", "raster", "_api.py"} <= packages, packages
    assert lengths[0][0] <= MAX_LINES, [x for x in lengths if x[0] > MAX_LINES]


def test_no_kernel_over_8_parameters():
    counts = sorted(((len(n.args.args), f"{p}:{n.name}") for p, n in _functions() if _is_kernel(n)), reverse=True)
    print("kernels with the most parameters:", counts[:4])
    assert len(counts) >= 5 and counts[0][0] <= MAX_KERNEL_PARAMS, counts


def test_every_array_goes_to_the_device():
    from volumen.core import Camera, Scene, Shading, TransferFunction
    from volumen.data import phantom
    from volumen.render.raycast import PER_VOLUME, Arrays, pack_frame

    vol = phantom("sphere", size=12)
    f = pack_frame(Scene(volume=vol, transfer=TransferFunction.preset("ct-bone"), shading=Shading(mode="none")),
                   Camera.orbit(vol), (4, 4))
    sent = []
    dev = f.device_arrays(lambda name, a, same: sent.append((name, same)) or a)
    assert [n for n, _ in sent] == list(Arrays._fields)
    assert {n for n, same in sent if same} == set(PER_VOLUME)
    assert all(x is y for x, y in zip(dev, f.arrays, strict=True))


def test_a_new_setting_needs_its_declaration_and_its_use_only():
    """A setting is a field with its default: a record with one more field is built by keyword like
    ``Settings`` and a compiled kernel reads the new field by name (no index, no argument list to change)."""
    from typing import NamedTuple

    from numba import njit

    from volumen.render.raycast import Settings

    fields = {n: (Settings.__annotations__[n], d) for n, d in Settings._field_defaults.items()}

    Extended = NamedTuple("Extended", [(n, t) for n, (t, _) in fields.items()] + [("exposure", float)])
    Extended.__new__.__defaults__ = tuple(d for _, d in fields.values()) + (2.5,)

    @njit
    def use(s):
        return s.exposure * s.ds

    s = Extended(ds=0.5)
    assert use(s) == 1.25 and np.isclose(s.ds0, Settings().ds0)
