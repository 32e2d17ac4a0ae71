"""A chunked volume in an interactive view: a coarse pyramid level while the user interacts, the full one when
idle -- the reduced-viewport idea (``volumen.render.render_reduced``) extended to resolution.

:func:`render_view` is what the desktop application's 3-D view and the notebook widget call for every frame:
a volume in memory goes to ``render_reduced`` as before; a chunked (OME-Zarr) volume is drawn out of core
(``volumen.render.bricked``) at the rendered viewport, from the level :func:`~._pyramid_levels.pick_level`
chooses for it (about one voxel per pixel) while ``interacting``, and from the volume's own level when idle.
The volume's own level is drawn from the volume itself, the coarser ones are opened once and kept (the last
:data:`KEPT`): their chunk caches, with what the bricks derived, stay warm from frame to frame while only the
camera moves.
"""

from __future__ import annotations

from collections import OrderedDict

from ..core import Image, is_chunked
from ..io import open_levels
from ..render import reduced_size, render_reduced, upscale
from ._pyramid_levels import open_volume, pick_level, render_bricked

__all__ = ["render_view", "VIEW_MEMORY", "KEPT"]

#: chunk cache of one interactive frame (bytes)
VIEW_MEMORY = 1 << 30
#: coarser levels kept open (each with its chunk cache) for the frames drawn while dragging
KEPT = 2
_OPEN: OrderedDict = OrderedDict()


def _opened(source, level: int):
    """The Volume of ``source`` at ``level``, opened once and kept (the last :data:`KEPT`)."""
    key = (str(source), int(level))
    vol = _OPEN.pop(key, None)
    _OPEN[key] = vol = open_volume(source, level) if vol is None else vol
    while len(_OPEN) > KEPT:
        _OPEN.popitem(last=False)
    return vol


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
    source, level, base = vol.meta.get("source"), 0, int(vol.meta.get("level", 0))
    if source is not None:
        level = max(base, pick_level(open_levels(source)[0], small, interacting))
    drawn = vol if source is None or level == base else _opened(source, level)  # each with its warm cache
    img = render_bricked(drawn, scene, camera, small, memory=memory, level=level)
    if small == tuple(int(s) for s in size):
        return img
    out = upscale(img, size)
    out.stats = dict(img.stats, reduced={"fraction": float(fraction), "render_size": small})
    return out
