"""Renderers: each takes (Scene, Camera, size) and returns an Image (docs/design.md section 1).

``render(scene, camera, size, device=None, technique="raycast", **options)`` is the entry point: the
device (:data:`DEVICES`: cpu, cuda, gl, auto) says where the picture is computed, the technique
(:data:`TECHNIQUES`: raycast, slicing, mesh) how, with its options (:func:`option_choices`);
a :class:`Technique` holds a name with its options and round-trips through JSON.
``render_volume(volume, ...)`` is a one-call convenience; ``PathTracer(scene, camera, size)``
accumulates path-traced samples progressively (``.step(n)``); ``render_reduced`` draws at a fraction of
the size and upscales (any device and technique: what a view shows while the user drags). The Numba
kernels are imported (and compiled, or loaded from Numba's cache) on first use; OpenGL on the first
rasterized picture. ``warm(jobs)`` compiles the kernels of several pictures side by side in child processes.
"""

from ._api import (
    clear_cache,
    default_look,
    default_mode,
    default_shading,
    default_transfer,
    render,
    render_volume,
)
from ._reduced import reduced_size, render_reduced, upscale
from ._techniques import (
    DEVICES,
    TECHNIQUES,
    Technique,
    choose_device,
    legacy_backend,
    option_choices,
    resolve_device,
)
from ._warm import warm

__all__ = ["render", "render_volume", "render_reduced", "reduced_size", "upscale", "default_transfer", "default_mode",
           "default_shading", "default_look",
           "clear_cache",
           "DEVICES", "TECHNIQUES", "Technique", "option_choices", "resolve_device", "choose_device", "legacy_backend",
           "PathTracer", "warm"]


def __getattr__(name):
    if name == "PathTracer":  # progressive path tracer; Numba loads here, not at import
        from .raycast import PathTracer

        return PathTracer
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
