"""The one locator of the shared data folder (real scans too large to ship, such as VMTK's aorta).

Looked for, in order: the folder named by the environment variable ``VOLUMEN_SHARED_DATA``;
``shared/data`` beside the repository (``<repo>/../shared/data``); ``shared/data`` beside the
folder holding the repository (``<repo>/../../shared/data``, where checkouts are worktrees in one
folder). No path of a particular machine is written here (``tests/test_house.py`` checks the
whole repository). :mod:`volumen.data` exports it; the fuzzers' seeds (``tools/fuzz/io``) use it from there.
"""

from __future__ import annotations

import os
from pathlib import Path

__all__ = ["shared_data", "shared_data_candidates", "ENV"]

#: the environment variable naming the shared data folder
ENV = "VOLUMEN_SHARED_DATA"
_REPO = Path(__file__).resolve().parents[2]  # volumen/data/_shared_data.py -> the repository (or site-packages)


def shared_data_candidates() -> list[Path]:
    """The folders searched, in order (the environment variable's first where it is set)."""
    env = os.environ.get(ENV, "")
    return ([Path(env)] if env else []) + [_REPO.parent / "shared" / "data", _REPO.parents[1] / "shared" / "data"]


def shared_data(*parts: str) -> Path | None:
    """The shared data folder, or the file ``parts`` inside it; None when no candidate holds it.

    Parameters
    ----------
    *parts : str
        A relative path inside the folder, e.g. ``("vmtk-aorta", "aorta.mha")``; the first
        candidate folder (:func:`shared_data_candidates`) where it exists wins. Without parts,
        the first candidate that is a folder.

    Returns
    -------
    Path or None
    """
    for folder in shared_data_candidates():
        path = folder.joinpath(*parts)
        if path.exists() if parts else path.is_dir():
            return path
    return None
