"""Compiled kernels are kept once per machine under the content key of every source they are compiled from
(``volumen.jit._stamp``, ``volumen.jit._locate``): another checkout of the same code loads them, an edited source
recompiles its group only and never loads a stale kernel, another CPU misses.

The first tests use a small package of their own (two groups of tiny kernels, compiled in a second or two) in
child processes with their own cache folder; the last draws with volumen's own ray caster from a copy of the
package at another path."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

HELPER = "from numba import njit\n\n\n@njit(cache=True)\ndef bump(x):\n    return x + 1.0\n"
KERNEL = textwrap.dedent('''
    from pathlib import Path

    from volumen.jit import stamp_sources

    _HERE = Path(__file__).resolve().parent
    stamp_sources([_HERE / "kern.py", _HERE / "helper.py"])

    from numba import njit  # noqa: E402

    from .helper import bump  # noqa: E402


    @njit(cache=True)
    def twice_bumped(x):
        return 2.0 * bump(x)
''')
OTHER = textwrap.dedent('''
    from pathlib import Path

    from volumen.jit import stamp_sources

    stamp_sources([Path(__file__).resolve()])

    from numba import njit  # noqa: E402


    @njit(cache=True)
    def halved(x):
        return 0.5 * x
''')
#: the child: calls both groups' kernels, prints their values and how many signatures each loaded or compiled
PROBE = textwrap.dedent('''
    import json
    from pkg.kern import twice_bumped
    from pkg.other import halved
    out = {}
    for name, f in (("kern", twice_bumped), ("other", halved)):
        value = f(1.0)
        out[name] = [value, sum(f.stats.cache_hits.values()), sum(f.stats.cache_misses.values())]
    print(json.dumps(out))
''')


def _package(where: Path) -> Path:
    pkg = where / "pkg"
    pkg.mkdir(parents=True)
    for name, text in (("__init__.py", ""), ("helper.py", HELPER), ("kern.py", KERNEL), ("other.py", OTHER)):
        (pkg / name).write_text(text)
    return where


def _probe(where: Path, cache: Path, **env) -> dict:
    """Run :data:`PROBE` with ``where`` first on the path and the kernels kept in ``cache``; its result."""
    environ = {k: v for k, v in os.environ.items()
               if k not in ("NUMBA_CACHE_DIR", "NUMBA_CPU_NAME", "VOLUMEN_KERNEL_DIR")}
    environ.update(VOLUMEN_CACHE_DIR=str(cache), PYTHONPATH=os.pathsep.join([str(where), str(ROOT)]), **env)
    done = subprocess.run([sys.executable, "-c", PROBE], env=environ, cwd=where, capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_a_copy_elsewhere_loads_what_the_first_compiled_and_an_edit_recompiles_its_group_only(tmp_path):
    cache = tmp_path / "cache"
    first = _probe(_package(tmp_path / "a"), cache)
    assert first == {"kern": [4.0, 0, 1], "other": [0.5, 0, 1]}  # cold: both compiled
    copy = tmp_path / "b"
    shutil.copytree(tmp_path / "a", copy)  # another checkout: another path, new modification times
    assert _probe(copy, cache) == {"kern": [4.0, 1, 0], "other": [0.5, 1, 0]}  # both loaded, nothing compiled
    helper = copy / "pkg" / "helper.py"
    helper.write_text(helper.read_text().replace("x + 1.0", "x + 2.0"))  # a one-line change to the callee
    edited = _probe(copy, cache)
    assert edited["kern"] == [6.0, 0, 1], "the edited group must recompile, not load the stale kernel"
    assert edited["other"] == [0.5, 1, 0], "the group that does not hold the edited file still loads"
    assert _probe(tmp_path / "a", cache)["kern"] == [4.0, 1, 0]  # the first checkout keeps its own kernels
    assert len(list((cache / "kernels").iterdir())) == 3  # a folder per content key: kern twice, other once


EDIT_WHILE_RUNNING = textwrap.dedent('''
    import json, pathlib
    from pkg.kern import twice_bumped
    helper = pathlib.Path(__import__("pkg.helper").helper.__file__)
    helper.write_text(helper.read_text().replace("x + 1.0", "x + 2.0"))  # edited under the running process
    print(json.dumps({"kern": [twice_bumped(1.0)]}))
''')


def test_a_source_edited_while_a_process_runs_never_gets_that_process_s_kernel(tmp_path):
    """The process compiles the code it imported: it is kept under the key of that code, so a later process of the
    edited sources compiles them instead of loading it."""
    where, cache = _package(tmp_path / "a"), tmp_path / "cache"
    environ = {k: v for k, v in os.environ.items()
               if k not in ("NUMBA_CACHE_DIR", "NUMBA_CPU_NAME", "VOLUMEN_KERNEL_DIR")}
    environ.update(VOLUMEN_CACHE_DIR=str(cache), PYTHONPATH=os.pathsep.join([str(where), str(ROOT)]))
    done = subprocess.run([sys.executable, "-c", EDIT_WHILE_RUNNING], env=environ, cwd=where, capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout.strip().splitlines()[-1])["kern"] == [4.0]  # the code it imported
    assert _probe(where, cache)["kern"] == [6.0, 0, 1]  # the edited code, compiled


def test_pruning_removes_old_key_folders_only(tmp_path):
    from volumen.jit import _locate

    old = time.time() - (_locate.KEEP_DAYS + 1) * 86400
    for name in ("0123456789abcdef01234567", "a-folder-of-the-users", "fedcba9876543210fedcba98"):
        (tmp_path / name).mkdir()
        os.utime(tmp_path / name, (old, old))
    _locate._prune(tmp_path, tmp_path / "fedcba9876543210fedcba98")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a-folder-of-the-users", "fedcba9876543210fedcba98"]


def test_another_cpu_misses(tmp_path):
    cache = tmp_path / "cache"
    where = _package(tmp_path / "a")
    _probe(where, cache)
    assert _probe(where, cache, NUMBA_CPU_NAME="generic") == {"kern": [4.0, 0, 1], "other": [0.5, 0, 1]}
    assert _probe(where, cache, NUMBA_CPU_NAME="generic")["kern"] == [4.0, 1, 0]


def test_numba_cache_dir_when_set_holds_the_kernels(tmp_path):
    """``NUMBA_CACHE_DIR`` (what ``volumen bench compile`` sets for a cold cache) is where kernels go when set."""
    where = _package(tmp_path / "a")
    _probe(where, tmp_path / "cache", NUMBA_CACHE_DIR=str(tmp_path / "numba"))
    assert len(list((tmp_path / "numba" / "volumen").iterdir())) == 2
    assert not (tmp_path / "cache").exists()


def test_the_key_is_the_contents_and_the_machine_not_the_time(tmp_path):
    from volumen.jit import machine, source_stamp

    a, b = tmp_path / "a.py", tmp_path / "b.py"
    a.write_text("x = 1\n")
    b.write_text("y = 2\n")
    key = source_stamp([a, b])
    os.utime(a, (1, 1))
    assert source_stamp([b, a]) == key  # neither the time nor the order
    a.write_text("x = 3\n")
    assert source_stamp([a, b]) != key
    numba_release, llvmlite_release, python, triple, cpu, features = machine()
    assert cpu and triple and numba_release and llvmlite_release and python == sys.version_info[:2]


def test_the_ray_casters_kernels_live_in_their_groups_folder(monkeypatch, tmp_path):
    from numba.core import caching

    from volumen.jit import group_folder, kernel_folder, source_stamp, stamped_with
    from volumen.render.raycast import _march

    locator = caching.CompileResultCacheImpl(_march._trace_tiles.py_func).locator
    group = stamped_with(_march.__file__)
    assert type(locator).__module__ == "volumen.jit._locate" and len(group) > 10
    assert locator.get_source_stamp() == source_stamp(group)
    assert Path(locator.get_cache_path()) == group_folder(group) / "render" / "raycast"
    assert group_folder(group).parent == kernel_folder()


def test_a_cache_folder_that_cannot_be_written_falls_back_beside_the_sources_still_keyed_on_the_group(monkeypatch):
    from numba.core import caching

    from volumen.jit import _locate, source_stamp, stamped_with
    from volumen.render.raycast import _march

    def refuse(files):
        raise PermissionError("read-only cache")

    monkeypatch.setattr(_locate, "group_folder", refuse)
    locator = caching.CompileResultCacheImpl(_march._trace_tiles.py_func).locator
    assert isinstance(locator, caching.InTreeCacheLocator) and type(locator).__module__ == "volumen.jit._locate"
    assert locator.get_source_stamp() == source_stamp(stamped_with(_march.__file__))


def test_where_neither_folder_can_be_written_a_temporary_one_holds_the_kernels_keyed_on_the_group(monkeypatch):
    import tempfile

    from numba.core import caching

    from volumen.jit import _locate, source_stamp, stamped_with
    from volumen.render.raycast import _march

    def refuse(files):
        raise PermissionError("read-only cache")

    monkeypatch.setattr(_locate, "group_folder", refuse)
    in_tree = caching.CacheImpl._locator_classes[1]
    monkeypatch.setattr(in_tree, "from_function", classmethod(lambda cls, f, p: None))  # __pycache__ read-only
    locator = caching.CompileResultCacheImpl(_march._trace_tiles.py_func).locator
    assert type(locator).__name__ == "_Temporary"
    assert Path(locator.get_cache_path()).is_relative_to(tempfile.gettempdir())
    assert locator.get_source_stamp() == source_stamp(stamped_with(_march.__file__))


def test_kernel_markers_sit_in_the_ray_casters_kernel_folder(monkeypatch, tmp_path):
    """The stand-ins' markers (``render._ready``: this kernel is in the cache) sit beside the kernels they speak for."""
    import volumen
    from volumen.jit import GROUPS, group_files, group_folder
    from volumen.render import _ready

    package = Path(volumen.__file__).resolve().parent
    files = {*group_files("render"), *(package / f for f in GROUPS["render"][1])}
    assert _ready.marker_dir() == group_folder(tuple(sorted(p.resolve() for p in files))) / "ready"
    monkeypatch.setattr(_ready, "marker_dir", lambda: tmp_path / "ready")
    monkeypatch.setattr(_ready, "_READY", set())
    _ready.note_ready(("a kernel key of this test",))
    monkeypatch.setattr(_ready, "_READY", set())  # a later session: only the marker is left
    assert _ready.is_ready(("a kernel key of this test",)) and len(list((tmp_path / "ready").glob("*"))) == 1


DRAW = textwrap.dedent('''
    import json
    import numpy as np
    from numba.core import event
    import volumen
    from volumen.core import Camera, Scene
    from volumen.render import render
    compiled = []

    class Count(event.Listener):
        def on_start(self, e):
            d = (e.data or {}).get("dispatcher")
            compiled.append(getattr(getattr(d, "py_func", None), "__module__", ""))

        def on_end(self, e):
            pass

    event.register("numba:compile", Count())
    z, y, x = np.mgrid[:24, :24, :24]
    v = volumen.Volume(((x - 12) ** 2 + (y - 12) ** 2 + (z - 12) ** 2 < 64).astype(np.float32), spacing=(1, 1, 1))
    img = render(Scene(volume=v, mode="mip"), Camera.orbit(v, view="left"), (16, 16))
    print(json.dumps({"file": volumen.__file__, "compiled": [m for m in compiled if m.startswith("volumen.")],
                      "max": float(np.asarray(img.rgba).max())}))
''')


def _draw(where: Path) -> dict:
    environ = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    environ["PYTHONPATH"] = str(where)
    done = subprocess.run([sys.executable, "-c", DRAW], env=environ, cwd=where, capture_output=True, text=True,
                          timeout=600)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.strip().splitlines()[-1])


@pytest.mark.skipif(os.environ.get("NUMBA_CACHE_DIR") is not None, reason="the test is about the shared cache")
def test_a_fresh_copy_of_volumen_draws_without_compiling(tmp_path):
    """A checkout at another path, every file new: the ray caster's kernels come from the machine's cache."""
    here = _draw(ROOT)  # compiles what no earlier test or run of this code did
    copy = tmp_path / "clone"
    shutil.copytree(ROOT / "volumen", copy / "volumen", ignore=shutil.ignore_patterns("__pycache__"))
    there = _draw(copy)
    assert Path(there["file"]).is_relative_to(copy)
    assert there["compiled"] == [], f"a copy of the same code compiled {there['compiled']}"
    assert there["max"] == here["max"] > 0
