"""One setup for everything the README shows: ``make demo`` installs every extra a user command needs, and each
optional package volumen imports is named with the extra that brings it."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

from volumen.errors import EXTRAS, MissingExtraError

ROOT = Path(__file__).resolve().parents[1]
#: the extras behind the README's user commands: view (gui), --device gl and the slicing and mesh techniques (gl),
#: OME-Zarr and batch (scale), volumen.show (notebook), fly -o x.mp4 (video)
USER_EXTRAS = {"gui", "gl", "scale", "notebook", "video", "report"}


def _optional_dependencies() -> dict[str, list[str]]:
    return tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]


def test_make_demo_installs_every_user_extra_and_no_test_tool():
    make = (ROOT / "Makefile").read_text()
    extras = set(re.search(r"^DEMO_EXTRAS\s*:=\s*(\S+)", make, flags=re.M).group(1).split(","))
    install = re.search(r"^define demo_install\n(.*?)^endef", make, flags=re.M | re.S).group(1)
    assert '-e ".[$(DEMO_EXTRAS)]"' in install
    for stamp in ("DEMO_STAMP", "README_STAMP"):  # the demo's venv and the README test's are made alike
        recipe = re.search(rf"^\$\({stamp}\):.*?\n((?:\t.*\n)+)", make, flags=re.M).group(1)
        assert "$(call demo_install," in recipe, stamp
    assert extras == USER_EXTRAS
    assert extras <= set(_optional_dependencies())


def test_every_optional_package_names_an_extra_that_brings_it():
    optional = _optional_dependencies()
    for module, extra in EXTRAS.items():
        assert extra in optional, f"{module}: no extra {extra!r} in pyproject.toml"
    assert str(MissingExtraError("PySide6.QtWidgets", "the desktop application")) == (
        "the desktop application needs PySide6: pip install 'volumen[gui]'")


#: variables set by volumen for its own child processes, not by a user
INTERNAL_VARIABLES = {"VOLUMEN_FUZZ_MEMORY"}


def test_every_environment_variable_is_documented():
    named = set()
    for path in [*(ROOT / "volumen").rglob("*.py"), ROOT / "Makefile"]:
        named |= set(re.findall(r"\bVOLUMEN_[A-Z][A-Z_]*[A-Z]\b", path.read_text(encoding="utf-8")))
    table = (ROOT / "README.md").read_text(encoding="utf-8").split("## Environment variables", 1)[1]
    documented = set(re.findall(r"^\| `(VOLUMEN_[A-Z_]+)", table, flags=re.M))
    assert named - INTERNAL_VARIABLES <= documented, sorted(named - INTERNAL_VARIABLES - documented)
    assert documented <= named, sorted(documented - named)
