"""Renderers: each takes (Scene, Camera, size) and returns an Image (DESIGN.md section 1).

``render(scene, camera, size, backend="cpu")`` is the entry point;
``render_volume(volume, ...)`` is a one-call convenience. The Numba kernels
are imported (and compiled, or loaded from Numba's cache) on first use.
"""

from ._api import BACKENDS, clear_cache, default_transfer, render, render_volume

__all__ = ["render", "render_volume", "default_transfer", "clear_cache", "BACKENDS"]
