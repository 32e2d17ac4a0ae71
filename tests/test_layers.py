"""The layers of docs/design.md section 1 as failing tests, not hopes."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_import_linter_contracts_hold():
    """`lint-imports` checks the contracts in pyproject.toml: layers point down, Qt only in app,
    renderers never read files."""
    exe = Path(sys.executable).with_name("lint-imports")
    if not exe.exists():
        pytest.fail("import-linter is not installed (it is in the 'test' extra)")
    env = dict(os.environ, PYTHONIOENCODING="utf-8", LC_ALL="C.UTF-8", LANG="C.UTF-8")
    proc = subprocess.run([str(exe), "--config", str(ROOT / "pyproject.toml"), "--no-cache"], cwd=ROOT,
                          capture_output=True, text=True, encoding="utf-8", errors="replace", env=env)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "0 broken" in proc.stdout


def test_import_volumen_is_light():
    """`import volumen` must not pull in the heavy or optional dependencies."""
    code = ("import sys, volumen; heavy = [m for m in ('numba', 'scipy', 'pydicom', 'nibabel', 'SimpleITK', "
            "'PySide6', 'moderngl', 'vtk', 'imageio') if m in sys.modules]; print(','.join(heavy))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.strip()
    assert out == "", f"import volumen loaded: {out}"


def test_the_layer_contract_is_the_floors_of_docs_design():
    """pyproject.toml's layers contract lists the floors of docs/design.md section 1's floor line, in its order."""
    import re
    import tomllib

    config = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    layers = next(c["layers"] for c in config["tool"]["importlinter"]["contracts"] if c["type"] == "layers")
    contract = [re.sub(r"\s+", "", layer.replace("volumen.", "")) for layer in layers]
    design = (ROOT / "docs" / "design.md").read_text(encoding="utf-8")
    line = next(ln for ln in design.splitlines() if ln.startswith("cli  >"))
    floors = [re.sub(r"\s+", "", f) for f in line.split(">")]
    assert contract == floors
    assert next(k for k, f in enumerate(floors) if "analysis" in f.split("|")) == floors.index("endoscopy") - 1


def test_import_volumen_measure_is_light():
    """The measurement model is numpy only at import: a notebook measuring a distance loads no DICOM or SR
    machinery (highdicom and pydicom come with the SR's reader and writer, when used)."""
    code = ("import sys, volumen.measure; heavy = [m for m in ('numba', 'scipy', 'pydicom', 'highdicom', 'PySide6', "
            "'moderngl') if m in sys.modules]; print(','.join(heavy))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.strip()
    assert out == "", f"import volumen.measure loaded: {out}"
