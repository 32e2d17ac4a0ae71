"""Every group of sources whose cached kernels are keyed together, declared once (docs/design.md section 9).

Numba checks only a kernel's own file; a kernel that inlines another file's functions, or freezes its arrays
into its machine code, is keyed on that file too (:mod:`._stamp`). :data:`GROUPS` names each group's files
by pattern inside the package, with the groups and files its kernels also compile from. Importing
:mod:`volumen.jit` registers all of them (:func:`register`), and every compiled module outside the ray
caster takes its decorator from :mod:`volumen.jit` (``from ..jit import njit``): no kernel can be defined
before its group is stamped, whatever order the packages are imported in (``tests/test_house.py`` checks).
"""

from __future__ import annotations

from pathlib import Path

from ._stamp import _PACKAGE, stamp_sources

__all__ = ["GROUPS", "group_files", "register"]

#: group -> (patterns of its own files, other groups and files its kernels compile from), in dependency order
GROUPS: dict[str, tuple[tuple[str, ...], tuple[str, ...]]] = {
    # the ray caster: the marching skeleton inlines the mode pieces, the lighting, the optical model, the
    # thread driver's work counter and the prefetch hint, and freezes the lighting model's constants
    "render": (("render/raycast/*.py", "render/optics.py"),
               ("jit/_threads.py", "jit/_prefetch.py", "core/_lighting.py")),
    # endoscopy's collision march, unfolded view and scores call the ray caster's sampling
    "endoscopy": (("endoscopy/**/*.py",), ("render",)),
    # marching cubes inlines _mc_rows' word helpers and freezes _mc_tables' arrays
    "marching cubes": (("surface/_mc_*.py",), ()),
    "mesh orientation": (("surface/_orient_kernel.py",), ()),
    "region growing": (("segment/_region_growing_kernel.py",), ()),
    "tube phantoms": (("data/_tubes.py",), ()),
}


def _files(patterns) -> list[Path]:
    return sorted({p for pattern in patterns for p in _PACKAGE.glob(pattern)})


def group_files(name: str) -> tuple[Path, ...]:
    """The files of group ``name`` (its own files, not those it also compiles from), sorted."""
    return tuple(_files(GROUPS[name][0]))


def register() -> None:
    """Stamp every group: each of its files keyed on the group, the files it names and the groups it names."""
    for own, also in GROUPS.values():
        extra = [f for name in also if name in GROUPS for f in group_files(name)]
        stamp_sources(_files(own), also=extra + _files(a for a in also if a not in GROUPS))
