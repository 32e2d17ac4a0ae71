"""Where volumen keeps things on this machine: its settings, its cache and, in the cache, the compiled kernels.

One definition for every package that writes outside the user's own files (``volumen.pacs`` keeps retrieved
series in :func:`cache_dir` ``/archives``, the application its recent files in :func:`config_dir`,
``volumen.jit`` the compiled kernels in :func:`kernel_dir`). Each honours the variable a user sets for it first,
then the XDG base-directory variable, then the folder under the home directory.

=====================  =====================================  =================================
folder                 variables, in order                    default
=====================  =====================================  =================================
:func:`config_dir`     ``VOLUMEN_CONFIG_DIR``,                ``~/.config/volumen``
                       ``XDG_CONFIG_HOME`` + ``/volumen``
:func:`cache_dir`      ``VOLUMEN_CACHE_DIR``,                 ``~/.cache/volumen``
                       ``XDG_CACHE_HOME`` + ``/volumen``
:func:`kernel_dir`     ``VOLUMEN_KERNEL_DIR``,                ``~/.cache/volumen/kernels``
                       ``NUMBA_CACHE_DIR`` + ``/volumen``,
                       :func:`cache_dir` + ``/kernels``
=====================  =====================================  =================================
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

__all__ = ["config_dir", "cache_dir", "kernel_dir"]


def _given(name: str) -> Path | None:
    """The folder a variable names, ``~`` expanded and made absolute (a later change of directory does not move
    it), or None where it is unset or empty."""
    value = os.environ.get(name)
    return Path(value).expanduser().absolute() if value else None


def _home() -> Path:
    """The home folder, or (a user with none: a container's, say) a folder of the user's in the temporary one."""
    try:
        return Path.home()
    except (RuntimeError, KeyError):
        return Path(tempfile.gettempdir()) / f"volumen-{os.getuid()}"


def _folder(own: str, xdg: str, fallback: str) -> Path:
    """``$own``, else ``$xdg/volumen``, else ``~/fallback/volumen``."""
    return _given(own) or (_given(xdg) or _home() / fallback) / "volumen"


def config_dir() -> Path:
    """``VOLUMEN_CONFIG_DIR``, else ``$XDG_CONFIG_HOME/volumen``, else ``~/.config/volumen``."""
    return _folder("VOLUMEN_CONFIG_DIR", "XDG_CONFIG_HOME", ".config")


def cache_dir() -> Path:
    """``VOLUMEN_CACHE_DIR``, else ``$XDG_CACHE_HOME/volumen``, else ``~/.cache/volumen``."""
    return _folder("VOLUMEN_CACHE_DIR", "XDG_CACHE_HOME", ".cache")


def kernel_dir(numba_cache_dir: str | None = None) -> Path:
    """Where compiled kernels are kept: ``VOLUMEN_KERNEL_DIR``, else ``<numba_cache_dir>/volumen`` where Numba's
    own cache folder is set (``NUMBA_CACHE_DIR``; the caller passes ``numba.config.CACHE_DIR``, which Numba read
    from it), else :func:`cache_dir` ``/kernels``."""
    if _given("VOLUMEN_KERNEL_DIR"):
        return _given("VOLUMEN_KERNEL_DIR")
    if numba_cache_dir is None:
        numba_cache_dir = os.environ.get("NUMBA_CACHE_DIR", "")
    if numba_cache_dir:
        return Path(numba_cache_dir) / "volumen"
    return cache_dir() / "kernels"
