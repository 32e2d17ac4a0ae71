"""Checks anyone can run on the house itself (issue 26): no path of one machine, short parameter lists, the design
document cited as it is, cached kernels stamped, one thread driver, unique test names, ruff clean."""

from __future__ import annotations

import ast
import importlib
import re
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: top-level folders that exist on one machine only (a checkout, a home, a mount); ``/usr/share`` (a
#: distribution's packages), ``/proc`` and ``/dev`` name the same thing everywhere and are allowed
_MACHINE_ROOTS = ("work", "home", "Users", "root", "mnt", "media", "opt", "srv", "scratch")
_MACHINE_PATH = re.compile(r"(?<![\w.~/-])/(?:" + "|".join(_MACHINE_ROOTS) + r")/[\w.-]+|\b[A-Z]:\\Users\\")
#: packages whose functions take at most this many parameters (more: a record, as ``render/raycast/_frame.py``)
MAX_PARAMETERS = 8
_RECORD_PACKAGES = ("volumen/endoscopy", "volumen/surface")


def _repository_files() -> list[Path]:
    """Files of the repository: tracked and untracked but not ignored (the working tree as it will be committed)."""
    out = subprocess.run(["git", "ls-files", "--cached", "--others", "--exclude-standard", "-z"], cwd=ROOT,
                         capture_output=True, check=True).stdout
    return [ROOT / name for name in out.decode().split("\0") if name and (ROOT / name).is_file()]


def test_no_absolute_path_of_a_particular_machine():
    """Data is found through ``volumen.data.shared_data`` (``VOLUMEN_SHARED_DATA`` or beside the repository)."""
    found = []
    for path in _repository_files():
        try:
            text = path.read_text(encoding="utf-8")
        except UnicodeDecodeError:
            continue  # pictures, compressed tables
        for n, line in enumerate(text.splitlines(), 1):
            found += [f"{path.relative_to(ROOT)}:{n}: {m.group(0)}" for m in _MACHINE_PATH.finditer(line)]
    print(f"{len(_repository_files())} files checked")
    assert not found, "\n".join(found)


def _parameters(node: ast.FunctionDef | ast.AsyncFunctionDef) -> int:
    a = node.args
    names = [p.arg for p in a.posonlyargs + a.args + a.kwonlyargs]
    extra = (a.vararg is not None) + (a.kwarg is not None)
    return len(names) - (names[:1] in (["self"], ["cls"])) + extra


def test_no_function_in_surface_or_endoscopy_takes_more_than_eight_parameters():
    """Long positional lists (a kernel's arrays and settings) are records there, as in the ray caster."""
    long = []
    for package in _RECORD_PACKAGES:
        for path in sorted((ROOT / package).rglob("*.py")):
            for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
                if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef) and _parameters(node) > MAX_PARAMETERS:
                    long.append(f"{path.relative_to(ROOT)}:{node.lineno} {node.name}: {_parameters(node)}")
    assert not long, "\n".join(long)


def test_the_design_document_is_in_the_repository_and_every_citation_finds_its_section():
    """Code, tests, README and the layer contract cite ``docs/design.md section N``: each N is a heading there."""
    design = (ROOT / "docs" / "design.md").read_text(encoding="utf-8")
    sections = {int(n) for n in re.findall(r"^## (\d+)\. ", design, flags=re.M)}
    cited: dict[int, list[str]] = {}
    for path in _repository_files():
        if path.suffix in (".py", ".md", ".toml") and path.name != "design.md":
            for n in re.findall(r"docs/design\.md section (\d+)", path.read_text(encoding="utf-8")):
                cited.setdefault(int(n), []).append(str(path.relative_to(ROOT)))
    print(f"sections {sorted(sections)}; cited {sorted(cited)} by {sum(map(len, cited.values()))} places")
    assert {1, 2, 3, 4, 5} <= sections
    assert len(cited) >= 4 and set(cited) <= sections, {n: cited[n] for n in set(cited) - sections}
    assert not re.search(r"(?<!docs/)DESIGN\.md", " ".join(p.read_text(encoding="utf-8") for p in _repository_files()
                                                            if p.suffix in (".py", ".toml")))


def _used_files(module) -> set[Path]:
    """Files of volumen whose compiled code or frozen arrays ``module``'s kernels can reach: dispatchers defined
    elsewhere, the implementations behind inlined pieces (``raycast._pieces``) and volumen modules it holds."""
    import types

    from numba.core.dispatcher import Dispatcher

    package = Path(importlib.import_module("volumen").__file__).resolve().parent
    used: set[Path] = set()
    for value in vars(module).values():
        if isinstance(value, Dispatcher):
            used.add(Path(value.py_func.__code__.co_filename).resolve())
        elif isinstance(value, types.FunctionType) and isinstance(getattr(value, "impls", None), dict):
            used.update(Path(fn.py_func.__code__.co_filename).resolve() for fn in value.impls.values())
        elif isinstance(value, types.ModuleType) and getattr(value, "__file__", None):
            used.add(Path(value.__file__).resolve())
    return {f for f in used if f.is_relative_to(package) and f != Path(module.__file__).resolve()}


_NO_KERNELS = ("volumen.app", "volumen.cli", "volumen.web", "volumen.notebook", "volumen.bench")


def test_every_cached_kernel_is_keyed_on_the_sources_it_is_compiled_from():
    """Numba checks only a kernel's own file: each module with ``cache=True`` kernels that uses another file's
    compiled functions (or tables) has that file, and that file's own group, in its stamp (``volumen.jit``)."""
    import pkgutil

    from numba.core.dispatcher import Dispatcher

    import volumen
    from volumen.jit import stamped_with

    checked, missing = [], []
    for info in pkgutil.walk_packages(volumen.__path__, "volumen."):
        if info.name.startswith(_NO_KERNELS) or info.name.endswith("__main__"):
            continue  # the top floors (Qt, servers, commands) compile nothing of their own
        module = importlib.import_module(info.name)
        own = Path(module.__file__).resolve()
        cached = [v for v in vars(module).values() if isinstance(v, Dispatcher)
                  and Path(v.py_func.__code__.co_filename).resolve() == own and type(v._cache).__name__ != "NullCache"]
        if not cached:
            continue
        key = set(stamped_with(own))
        checked.append(info.name)
        if not key:  # every cached kernel is kept in the machine's kernel cache, under its sources' contents
            missing.append(f"{info.name}: cached kernels of a file not registered with volumen.jit.stamp_sources")
        missing += [f"{info.name}.{d.py_func.__name__} not stamped" for d in cached
                    if type(d._cache._impl._locator).__module__ != "volumen.jit._locate"]
        for used in _used_files(module):
            if used not in key or not set(stamped_with(used)) <= key:
                missing.append(f"{info.name} uses {used.name}, not in its stamp")
    print(f"{len(checked)} modules with cached kernels: {', '.join(checked)}")
    assert {"volumen.render.raycast._march", "volumen.surface._mc_kernel", "volumen.endoscopy.path._collision"} <= set(
        checked)
    assert not missing, "\n".join(missing)


#: the pools that are not compiled passes: the one OpenGL thread, the web server's render thread and its bounded
#: pool of request work
_OTHER_POOLS = ("volumen/render/raster/_context.py", "volumen/web/_server.py", "volumen/web/_handlers.py")


def test_every_compiled_pass_runs_on_the_one_thread_driver():
    """No ``prange`` / ``parallel=True`` (a second compile of the kernel's machine code, a fixed share per
    thread) and no thread pool of its own outside ``volumen/jit/_threads.py`` (docs/design.md section 8)."""
    found = []
    for path in sorted((ROOT / "volumen").rglob("*.py")):
        name, text = str(path.relative_to(ROOT)), path.read_text(encoding="utf-8")
        if not any(word in text for word in ("prange", "ThreadPoolExecutor", "parallel")):
            continue  # nothing to look at: skip the parse
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, ast.Name | ast.Attribute | ast.alias):
                ident = node.id if isinstance(node, ast.Name) else node.attr if isinstance(node, ast.Attribute) \
                    else node.name
                if ident == "prange" or (ident == "ThreadPoolExecutor" and name != "volumen/jit/_threads.py"
                                         and name not in _OTHER_POOLS):
                    found.append(f"{name}:{getattr(node, 'lineno', '?')} {ident}")
            elif isinstance(node, ast.keyword) and node.arg == "parallel" and getattr(node.value, "value", 0) is True:
                found.append(f"{name}:{node.value.lineno} parallel=True")
    assert not found, "\n".join(found)


def test_every_test_module_has_a_name_of_its_own():
    """pytest imports the test folders' modules by their bare names (rootdir conftest, no packages): two files of
    one name in two folders break collection of the second (tests/render/test_display.py did, in CI)."""
    seen: dict[str, Path] = {}
    clashes = []
    for p in sorted((ROOT / "tests").rglob("*.py")):
        if p.name in ("conftest.py", "__init__.py"):
            continue
        if p.name in seen:
            clashes.append(f"{seen[p.name].relative_to(ROOT)} and {p.relative_to(ROOT)}")
        seen.setdefault(p.name, p)
    assert not clashes, clashes


def test_ruff_is_clean():
    """``ruff check volumen tests tools`` (the pinned ruff of the test extra; the rules in pyproject.toml)."""
    import sys

    exe = Path(sys.executable).with_name("ruff")
    assert exe.exists(), "ruff is not installed (it is in the 'test' extra: pip install -e '.[test]')"
    out = subprocess.run([str(exe), "check", "volumen", "tests", "tools"], cwd=ROOT, capture_output=True, text=True)
    assert out.returncode == 0, out.stdout + out.stderr
