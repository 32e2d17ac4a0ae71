"""Real sample volumes installed on the machine (not shipped with volumen).

The MRI templates of MRIcron (Debian package ``mricron-data``) live in
``/usr/share/mricron/templates``: ``ch2better`` (the Colin27 brain in MNI space,
0.5 mm), ``ch2``, ``ch2bet``, label atlases (``aal``, ``brodmann``...) and more.
Every NIfTI file found in the search folders is a sample named after its file
(``ch2better.nii.gz`` -> ``"ch2better"``); ``ALIASES`` adds friendly names.
"""

from __future__ import annotations

from pathlib import Path

from ..core import Volume
from ..errors import SampleDataMissingError

__all__ = ["sample", "samples", "SEARCH_DIRS", "ALIASES"]

SEARCH_DIRS: tuple[Path, ...] = (Path("/usr/share/mricron/templates"),)
ALIASES = {"mni-brain": "ch2better"}
_INSTALL_HINT = "on Debian: sudo apt-get install mricron-data"
_SUFFIXES = (".nii.gz", ".nii")


def _stem(path: Path) -> str | None:
    for suffix in _SUFFIXES:
        if path.name.endswith(suffix):
            return path.name[: -len(suffix)]
    return None


def samples() -> dict[str, Path]:
    """Installed samples: name -> file path, sorted by name, aliases included (empty when none).

    Scans :data:`SEARCH_DIRS` each call (cheap: one directory listing per folder).
    """
    found: dict[str, Path] = {}
    for folder in SEARCH_DIRS:
        if not folder.is_dir():
            continue
        for path in sorted(folder.iterdir()):
            name = _stem(path)
            if name is not None and path.is_file():
                found.setdefault(name, path)
    for alias, target in ALIASES.items():
        if target in found:
            found[alias] = found[target]
    return dict(sorted(found.items()))


def sample(name: str = "mni-brain") -> Volume:
    """Load an installed sample volume by name (see :func:`samples`) through :func:`volumen.io.load`.

    Returns the volume as the reader gives it (data ``[z, y, x]``, affine to RAS+ mm),
    named ``name``, with ``meta["sample"] = name``.

    Raises
    ------
    SampleDataMissingError
        When the sample is not installed; the message says how to install it
        ("on Debian: sudo apt-get install mricron-data") and lists what is installed.
    """
    from ..io import load

    available = samples()
    path = available.get(name)
    if path is None:
        target = ALIASES.get(name, name)
        where = ", ".join(str(d) for d in SEARCH_DIRS)
        have = f"; installed: {', '.join(available)}" if available else ""
        raise SampleDataMissingError(
            None, f"sample {name!r} ({target}.nii.gz, MRIcron templates) is not installed in {where}; "
                  f"{_INSTALL_HINT}{have}")
    vol = load(path)
    vol.name = name
    vol.meta["sample"] = name
    return vol
