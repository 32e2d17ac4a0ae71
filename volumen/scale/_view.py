"""A chunked volume in an interactive view: a coarse pyramid level while the user interacts, the full one when
idle -- the reduced-viewport idea (``volumen.render.render_reduced``) extended to resolution.

:func:`render_view` is what the desktop application's 3-D view and the notebook widget call for every frame:
a volume in memory goes to ``render_reduced`` as before; a chunked (OME-Zarr) volume is drawn out of core
(``volumen.render.bricked``) at the rendered viewport, from the level :func:`~._outofcore.pick_level`
chooses for it (about one voxel per pixel) while ``interacting``, and from the volume's own level when idle.
"""

from __future__ import annotations

from ..core import Image, is_chunked
from ..io import open_levels
from ..render import reduced_size, render_reduced, upscale
from ._outofcore import pick_level, render_bricked

__all__ = ["render_view", "VIEW_MEMORY"]

#: chunk cache of one interactive frame (bytes)
VIEW_MEMORY = 1 << 30


def render_view(scene, camera, size, fraction: float = 1.0, *, interacting: bool = False, memory=VIEW_MEMORY,
                **how) -> Image:
    """The picture of ``scene`` for a view of ``size = (width, height)`` drawn at ``fraction`` of it, upscaled.

    ``how`` (``device``, ``technique``, options) goes to ``render_reduced`` for a volume in memory; a chunked
    volume is ray cast on the CPU, ``stats["level"]`` naming the pyramid level drawn.
    """
    vol = scene.volume
    if vol is None or not is_chunked(vol.data):
        return render_reduced(scene, camera, size, fraction, **how)
    small = reduced_size(size, fraction)
    source, level = vol.meta.get("source"), 0
    if source is not None:
        base = int(vol.meta.get("level", 0))
        level = max(base, pick_level(open_levels(source)[0], small, interacting))
    img = render_bricked(source if source is not None else vol, scene, camera, small, memory=memory, level=level)
    if small == tuple(int(s) for s in size):
        return img
    out = upscale(img, size)
    out.stats = dict(img.stats, reduced={"fraction": float(fraction), "render_size": small})
    return out
