"""Checks anyone can run on the house itself: no path of one machine, short parameter lists, the design document
cited as it is, cached kernels stamped and compiled through volumen.jit, one thread driver, unique test names,
ruff clean, one name per concept, no hand-kept file lists, no issue numbers in comments."""

from __future__ import annotations

import ast
import importlib
import io
import re
import subprocess
import tokenize
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


# --- one name per concept, no hand-kept file lists, no issue numbers in comments ---------------------------------

#: module names that are one role in every package that has them, and why
SAME_ROLE_MODULES = {
    "__init__": "a package",
    "_api": "a package's public entry functions (load/save, render, the archive's find/series)",
    "_bench": "a package's benchmark, run by `volumen bench` (web: the page's frame rate, surface: marching cubes)",
    "_screenshot": "a front end saving its own view as PNG (the application's window, the page in Chromium)",
    "_slices": "the three slice views: computed in core, shown by each front end (web, notebook, cli)",
    "_mesh": "a triangle mesh: the Mesh type (surface) and its drawing on OpenGL (render/raster)",
    "_lightvol": "the light volume on each device: the CPU kernels (render/raycast) and CUDA's (render/cuda)",
    "_composite": "the over operator: along a ray (render/raycast) and of bricks' partial pictures (render/bricked)",
}
#: folders whose modules are named after what they drive or measure, and why
DRIVER_FOLDERS = {
    "volumen/cli": "a command's module is named after its sub-command, the thing it drives",
    "volumen/bench": "a benchmark's module is named after `volumen bench NAME`, the thing it measures",
}
#: class names that are one concept in two forms, and why
SAME_CONCEPT_CLASSES = {
    "Isosurface": "the scene's isosurface (core) and the same settings as the kernels' record (render/raycast)",
}


def shared_names(root: Path) -> list[str]:
    """Module basenames and top-level class names that two files under ``root`` (a ``volumen`` folder) share,
    outside the declared lists above: each a line ``name: file, file``."""
    modules: dict[str, list[str]] = {}
    classes: dict[str, list[str]] = {}
    for path in sorted(root.rglob("*.py")):
        rel = path.relative_to(root.parent).as_posix()
        if not any(rel.startswith(folder + "/") for folder in DRIVER_FOLDERS) and path.stem not in SAME_ROLE_MODULES:
            modules.setdefault(path.stem, []).append(rel)
        for node in ast.parse(path.read_text(encoding="utf-8")).body:
            if isinstance(node, ast.ClassDef) and node.name not in SAME_CONCEPT_CLASSES:
                classes.setdefault(node.name, []).append(rel)
    return [f"{kind} {name}: {', '.join(files)}" for kind, table in (("module", modules), ("class", classes))
            for name, files in sorted(table.items()) if len(files) > 1]


def test_no_two_concepts_share_a_module_or_class_name(tmp_path):
    """Two modules (outside the declared roles and the command and benchmark folders) or two classes of one name
    are two concepts under one name: rename the one whose name does not say what it holds."""
    planted = tmp_path / "volumen"
    for rel, text in (("io/_march.py", "class Frame:\n    pass\n"), ("render/_march.py", "class Frame:\n    pass\n"),
                      ("cli/_render.py", ""), ("render/_render.py", ""), ("io/_api.py", ""), ("web/_api.py", "")):
        (planted / rel).parent.mkdir(parents=True, exist_ok=True)
        (planted / rel).write_text(text)
    assert shared_names(planted) == ["module _march: volumen/io/_march.py, volumen/render/_march.py",
                                     "class Frame: volumen/io/_march.py, volumen/render/_march.py"]
    shared = shared_names(ROOT / "volumen")
    assert not shared, "\n".join(shared)


#: what the files of a folder are, by suffix: a literal naming two or more of them is a hand-kept list
_LISTED_SUFFIXES = (".js", ".mjs", ".html", ".css", ".glsl", ".vert", ".frag", ".wgsl")


#: a name that says it holds files of a folder
_FILE_LIST_NAME = re.compile(r"(?i)files|shaders|static|scripts")


def _strings(node) -> list[str]:
    return [e.value for e in getattr(node, "elts", ()) if isinstance(e, ast.Constant) and isinstance(e.value, str)]


def hand_kept_lists(source: str) -> list[int]:
    """Lines of ``source`` (Python) holding a list, tuple or set literal of two or more file names with a
    static-file or shader suffix, or of two or more strings assigned to a name that says it holds files
    (``SHADER_FILES = ("mesh", "slicing")``): files a folder holds, listed by hand instead of found there."""
    suffixed = re.compile(r"[\w.-]+(" + "|".join(map(re.escape, _LISTED_SUFFIXES)) + ")")
    found = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.List | ast.Tuple | ast.Set) and \
                sum(bool(suffixed.fullmatch(s)) for s in _strings(node)) >= 2:
            found.add(node.lineno)
        elif isinstance(node, ast.Assign | ast.AnnAssign) and isinstance(node.value, ast.List | ast.Tuple | ast.Set):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            if any(_FILE_LIST_NAME.search(getattr(t, "id", "")) for t in targets) and len(_strings(node.value)) >= 2:
                found.add(node.lineno)
    return sorted(found)


def hand_kept_lists_in_the_house(skip: tuple[str, ...] = ()) -> list[str]:
    """``file:line`` of each hand-kept file list in ``volumen/``, but for the folders ``skip``."""
    return [f"{path.relative_to(ROOT)}:{line}" for path in sorted((ROOT / "volumen").rglob("*.py"))
            if not path.relative_to(ROOT).as_posix().startswith(skip)
            for line in hand_kept_lists(path.read_text(encoding="utf-8"))]


def test_no_hand_kept_file_list():
    """Static files and shaders are found in their folders: no literal list of them in ``volumen/``."""
    assert hand_kept_lists('FILES = ("index.html", "main.js")\nSTAGES = ["a.vert", "a.frag"]\n'
                           'SHADER_FILES = ("preamble", "mesh")\n') == [1, 2, 3]
    assert hand_kept_lists('TYPES = {".js": "text/javascript"}\nONE = ("main.js",)\nMODES = ("mip", "iso")\n') == []
    found = hand_kept_lists_in_the_house()
    assert not found, "\n".join(found)


#: the word issue (or issues) and a number, or a number right after a hash sign; not an upstream project's
#: ``owner/name`` before the hash, nor a CSS colour
_ISSUE = re.compile(r"\bissues? #?\d+|(?<![\w/.&-])#\d+\b(?![\w-])", re.IGNORECASE)


def _python_comments(source: str) -> list[tuple[int, str]]:
    """(line, text) of each comment and docstring of a Python source."""
    out = [(tok.start[0], tok.string) for tok in tokenize.generate_tokens(io.StringIO(source).readline)
           if tok.type == tokenize.COMMENT]
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef):
            doc = ast.get_docstring(node, clean=False)
            if doc:
                out.append((node.body[0].lineno, doc))
    return out


def _other_comments(path: Path, text: str) -> list[tuple[int, str]]:
    """(line, text) of each comment of a JavaScript, GLSL, CSS, HTML or Makefile source."""
    if path.name == "Makefile" or path.suffix == ".mk":
        return [(i, line) for i, line in enumerate(text.splitlines(), 1) if line.lstrip().startswith("#")]
    pattern = {".html": r"<!--.*?-->", ".css": r"/\*.*?\*/"}.get(path.suffix, r"//[^\n]*|/\*.*?\*/")
    return [(text.count("\n", 0, m.start()) + 1, m.group()) for m in re.finditer(pattern, text, re.S)]


def issue_citations(path: Path, text: str) -> list[str]:
    """``line: comment`` for each comment or docstring of ``path`` that cites an issue number."""
    comments = _python_comments(text) if path.suffix == ".py" else _other_comments(path, text)
    return [f"{line}: {_ISSUE.search(c).group()}" for line, c in comments if _ISSUE.search(c)]


#: where comments explain the code as it is
_COMMENTED = ("volumen", "tests", "tools")
_COMMENTED_SUFFIXES = (".py", ".js", ".mjs", ".glsl", ".css", ".html")


def _commented_files(skip: tuple[str, ...] = ()) -> list[Path]:
    files = [ROOT / "Makefile"] + [p for folder in _COMMENTED for p in sorted((ROOT / folder).rglob("*"))
                                   if p.suffix in _COMMENTED_SUFFIXES and "node_modules" not in p.parts]
    return [p for p in files if not p.relative_to(ROOT).as_posix().startswith(skip)]


def issue_citations_in_the_house(skip: tuple[str, ...] = ()) -> list[str]:
    """``file:line: citation`` for each comment or docstring citing an issue in ``volumen/``, ``tests/``,
    ``tools/`` and the Makefile, but for the folders ``skip`` (paths from the repository root)."""
    return [f"{p.relative_to(ROOT)}:{hit}" for p in _commented_files(skip)
            for hit in issue_citations(p, p.read_text(encoding="utf-8"))]


def test_no_comment_cites_an_issue():
    """Comments and docstrings explain the code as it is, without issue numbers (the tracker's history is in git)."""
    planted = '"""Issue 27: fast."""\nX = 1  # see #27\nY = "#27"  # numba/numba#9489 is upstream\n'
    assert issue_citations(Path("a.py"), planted) == ["2: #27", "1: Issue 27"]
    assert issue_citations(Path("a.js"), "// fixed in issue 3\nconst c = '#333';\n") == ["1: issue 3"]
    assert issue_citations(Path("Makefile"), "# issues 12 and 13\nA := 1 # 2\n") == ["1: issues 12"]
    found = issue_citations_in_the_house()
    assert not found, "\n".join(found)


# --- one place for compiled code: volumen.jit -----------------------------------------------------------------------

#: Numba's decorators that compile: a module takes them from :mod:`volumen.jit`, whose import stamps every group
_COMPILING = {"njit", "jit", "vectorize", "guvectorize", "cfunc", "stencil", "generated_jit"}
#: the one folder that takes Numba's decorators itself and registers the groups (``volumen.jit``)
_OWN_REGISTRATION = ("volumen/jit/",)


def numba_decorator_uses(source: str) -> list[int]:
    """Lines of ``source`` that take a compiling decorator from Numba itself (``from numba import njit``,
    ``@numba.njit``) or register sources outside the table (``stamp_sources(...)``)."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.ImportFrom) and node.module == "numba" and \
                any(a.name in _COMPILING for a in node.names):
            found.append(node.lineno)
        elif isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id == "numba" \
                and node.attr in _COMPILING:
            found.append(node.lineno)
        elif isinstance(node, ast.Call) and getattr(node.func, "id", getattr(node.func, "attr", "")) == "stamp_sources":
            found.append(node.lineno)
    return sorted(found)


def _cached_kernel_files() -> set[Path]:
    """Files of volumen with a ``cache=True`` compiled function."""
    out = set()
    for path in (ROOT / "volumen").rglob("*.py"):
        text = path.read_text(encoding="utf-8")
        if "cache=True" in text and any(isinstance(n, ast.keyword) and n.arg == "cache"
                                        and getattr(n.value, "value", None) is True for n in ast.walk(ast.parse(text))):
            out.add(path.resolve())
    return out


def test_compiled_code_goes_through_volumen_jit():
    """Every compiled module takes its decorator from ``volumen.jit`` (so its set-up and every group's stamp come
    first, whatever the import order: no module has to be imported "first"), and every file with cached kernels
    is in a group of ``volumen.jit.GROUPS``, registered as the table says."""
    assert numba_decorator_uses("from numba import njit, types\nimport numba\nf = numba.njit(cache=True)(g)\n"
                                "stamp_sources([__file__])\n") == [1, 3, 4]
    assert numba_decorator_uses("from numba import types\nfrom ..jit import njit, run_parts\n") == []
    found = [f"{p.relative_to(ROOT)}:{line}" for p in sorted((ROOT / "volumen").rglob("*.py"))
             if not p.relative_to(ROOT).as_posix().startswith(_OWN_REGISTRATION)
             for line in numba_decorator_uses(p.read_text(encoding="utf-8"))]
    assert not found, "take the decorator from volumen.jit, declare the group in volumen.jit.GROUPS:\n" + \
        "\n".join(found)
    import volumen.render.raycast  # noqa: F401 - its kernels defined, to compare their stamps with the table's
    from volumen.jit import GROUPS, group_files, stamped_with

    grouped = {f for name in GROUPS for f in group_files(name)}
    assert not {p for p in _cached_kernel_files() if p not in grouped}, "cached kernels outside volumen.jit.GROUPS"
    for name in GROUPS:
        for f in group_files(name):
            assert set(group_files(name)) <= set(stamped_with(f)), (name, f)
    render = set(stamped_with(group_files("render")[0]))
    assert all(set(stamped_with(f)) == render for f in group_files("render"))
    assert render <= set(stamped_with(group_files("endoscopy")[0]))


def test_test_helpers_are_imported_by_their_package_name():
    """Test helpers are modules of the ``tests`` tree, imported by their full name (``from tests.io.dicom_factory
    import write_series``; pytest's ``pythonpath`` holds the repository root): no test edits ``sys.path``."""
    edits = re.compile(r"\bsys\.path\.(insert|append|extend)\(|\bsys\.path\s*(\[|\+?=)")
    assert edits.search("sys.path." + "insert(0, here)") and not edits.search("from tests.io import dicom_factory")
    found = [f"{p.relative_to(ROOT)}:{i}" for p in sorted((ROOT / "tests").rglob("*.py"))
             for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1) if edits.search(line)]
    assert not found, "\n".join(found)


#: the folders a path in the design document is read from: the repository's, the package's, the renderers'
_DESIGN_BASES = ("", "volumen", "volumen/render", "docs")


def design_paths_missing(text: str) -> list[str]:
    """The file paths ``text`` names in backticks (``render/raycast/_march.py``, ``jit/_locate``,
    ``endoscopy/flight/_scores.score_flight``) that start at a folder of the repository and are not there.
    Placeholders (``io/_FORMAT.py``), globs, URLs, environment variables and folders outside the repository
    are not paths of it."""
    missing = []
    for token in re.findall(r"`([^`\s]+/[^`\s]*)`", text):
        if re.search(r"[*<>$~]|://|\.\.\.|^[.@/]|[A-Z]{3,}", token):
            continue
        head, _, last = token.rpartition("/")
        first = token.split("/")[0]
        if not any((ROOT / base / first).exists() for base in _DESIGN_BASES):
            continue  # not a folder of the repository (shared/data beside it, a package's own names)
        name = last if re.search(r"\.(py|md|glsl|js|mjs|toml|json|npz|css|html)$", last) else \
            re.split(r"[.(:]", last)[0]
        if not any((ROOT / base / head / cand).exists() for base in _DESIGN_BASES
                   for cand in (name, name + ".py")):
            missing.append(token)
    return missing


def test_every_file_path_the_design_names_exists():
    """``docs/design.md`` is a map: each file or folder it names is in the repository, and it has the flow diagram
    and the how-to section for each extension point."""
    assert design_paths_missing("`render/raycast/_march.py` `jit/_locate` `io/_FORMAT.py` `shared/data`") == []
    assert design_paths_missing("`render/raycast/_gone.py` `endoscopy/lumen/_gone.run`") == [
        "render/raycast/_gone.py", "endoscopy/lumen/_gone.run"]
    design = (ROOT / "docs" / "design.md").read_text(encoding="utf-8")
    assert not design_paths_missing(design), design_paths_missing(design)
    how_to = design[design.index("## 11. How to add"):]
    assert all(f"- **A {what}.**" in how_to for what in ("reader", "mode", "shading model", "technique", "front end"))
    assert "io.load" in design and "core.Image" in design and "render.render(" in design  # the flow diagram
