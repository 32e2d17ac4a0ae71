"""The browser viewer's code (``volumen/web/static``) linted by ESLint and type checked by TypeScript (``tsc``
with ``checkJs`` over its JSDoc types), configured by the repository's ``eslint.config.mjs`` and
``jsconfig.json``: the two commands of ``make lint-web``, run with the exact versions ``make web-deps``
installs into ``.web-deps/``. Each must exit 0; its output is printed when it does not. Without node or
those packages the tests skip with the reason printed."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
MODULES = ROOT / ".web-deps" / "node_modules"
#: what each tool needs from npm besides itself: the configuration's imports and the WebXR types
NEEDS = {"eslint": ("eslint", "@eslint/js", "globals"), "tsc": ("typescript", "@types/webxr")}


def skip(reason: str):
    print(f"skipped: {reason}")
    pytest.skip(reason)


def tool(name: str) -> Path:
    if shutil.which("node") is None:
        skip(f"node is not installed: {name} not run (`make web-deps` installs it with npm)")
    for package in NEEDS[name]:
        if not (MODULES / package / "package.json").exists():
            skip(f"the npm package {package} is not installed ({MODULES / package} is missing: "
                 "`make web-deps` installs it)")
    return MODULES / ".bin" / name


def run(*command) -> tuple[int, str]:
    """``(exit status, what it printed)`` of ``command`` in the repository (printed too when it fails)."""
    p = subprocess.run([str(c) for c in command], cwd=ROOT, capture_output=True, text=True, timeout=600)
    out = (p.stdout + p.stderr).strip()
    if p.returncode != 0:
        print(out)
    return p.returncode, f"{' '.join(str(c) for c in command)} exited {p.returncode}:\n{out}"


def test_eslint_passes_on_the_browser_code():
    code, said = run(tool("eslint"), "--max-warnings", "0", "volumen/web/static")
    assert code == 0, said


def test_tsc_type_checks_the_browser_code():
    code, said = run(tool("tsc"), "-p", "jsconfig.json")
    assert code == 0, said
