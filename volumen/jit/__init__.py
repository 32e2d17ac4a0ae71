"""Compiled code's machinery, one floor below every package that compiles (docs/design.md sections 8 and 9).

* :func:`run_parts`, :func:`run_claiming`, :func:`claim`, :func:`fetch_add`: the one thread driver of every
  compiled pass (ray casting, marching cubes, per-volume precomputation);
* :func:`prefetch`: a hint that an array element will be read soon (nothing on the GPU);
* :func:`njit`: Numba's decorator, taken from here by every compiled module, so that this package's set-up
  (below) has run before any kernel is defined;
* :func:`stamp_sources`, :func:`source_stamp`: the groups of sources a cached kernel is compiled from, and their
  content key; :data:`GROUPS` declares every group once, all registered on import; :mod:`._locate` keeps each
  group's kernels in one folder per key that every checkout on this machine shares (:func:`kernel_folder`,
  installed on import);
* :mod:`._savelock`: one process at a time writes a cache index (installed on import);
* :mod:`._inlining`: Numba's inliner without its repeated work (patched on import; :func:`inline_only`,
  :func:`install_cuda` for numba-cuda's copy of the compiler, :func:`inlining_active`);
* :data:`NUMBA_TESTED`, :func:`patches_allowed` (numba-cuda's: :data:`NUMBA_CUDA_TESTED`,
  :func:`cuda_patches_allowed`): the fence around the patches to Numba's internals;
* :func:`announce`: one line when a command starts compiling (the command line's, for its drawing commands).

Importing this package imports Numba; ``import volumen`` does not import it.
"""

from numba import njit

from ._groups import GROUPS, group_files
from ._groups import register as _register_groups
from ._guard import (
    ENV,
    NUMBA_CUDA_TESTED,
    NUMBA_TESTED,
    cuda_patches_allowed,
    in_tested_range,
    numba_version,
    patches_allowed,
)
from ._inlining import active as inlining_active
from ._inlining import inline_only, install_cuda
from ._locate import group_folder, kernel_folder
from ._locate import install as _locate_kernels
from ._notice import announce
from ._prefetch import prefetch
from ._savelock import install as _lock_cache_saves
from ._stamp import machine, source_stamp, stamp_sources, stamped_with
from ._threads import claim, fetch_add, run_claiming, run_parts

_lock_cache_saves()
_locate_kernels()
_register_groups()

__all__ = ["njit", "GROUPS", "group_files", "run_parts", "run_claiming", "claim", "fetch_add", "prefetch",
           "stamp_sources", "stamped_with", "source_stamp", "machine", "kernel_folder", "group_folder", "NUMBA_TESTED",
           "NUMBA_CUDA_TESTED", "ENV", "numba_version", "in_tested_range", "patches_allowed", "cuda_patches_allowed",
           "announce", "inlining_active", "inline_only", "install_cuda"]
