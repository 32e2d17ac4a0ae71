"""Renderers: each takes (Scene, Camera, size) and returns an Image (DESIGN.md section 1).

``render(scene, camera, size, backend="cpu")`` is the entry point;
``render_volume(volume, ...)`` is a one-call convenience; ``PathTracer(scene,
camera, size)`` accumulates path-traced samples progressively (``.step(n)``). The Numba kernels
are imported (and compiled, or loaded from Numba's cache) on first use.
"""

from ._api import BACKENDS, clear_cache, default_transfer, render, render_volume
from .raster import render_reduced

__all__ = ["render", "render_volume", "render_reduced", "default_transfer", "clear_cache", "BACKENDS", "PathTracer"]


def __getattr__(name):
    if name == "PathTracer":  # progressive path tracer; Numba loads here, not at import
        from .raycast import PathTracer

        return PathTracer
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
