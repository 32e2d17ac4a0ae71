"""Out of core from a path: an OME-Zarr image's pyramid level opened lazily and drawn brick by brick.

The drawing itself is the renderer's (``volumen.render.bricked``: what ``volumen.render`` does with a
chunked volume); this module adds the storage side: :func:`open_volume` reads a level of a path as a
chunked Volume (its per-chunk value ranges travel with its data), :func:`render_bricked` draws a path or a
Volume, and :func:`pick_level` chooses the level an interactive view draws while the user drags (about one
voxel per pixel) and level 0 when idle.
"""

from __future__ import annotations

from pathlib import Path

from ..core import Image
from ..io import load
from ..render import bricked
from ..render.bricked import MEMORY

__all__ = ["render_bricked", "open_volume", "pick_level"]


def open_volume(source, level: int = 0):
    """The Volume of ``source``: a path (OME-Zarr / Zarr) read lazily at pyramid ``level``, or a Volume as it is."""
    return load(source, format="zarr", level=level) if isinstance(source, (str, Path)) else source


def pick_level(levels, size, interacting: bool) -> int:
    """Level 0 when idle; while interacting the finest level with at most about one voxel per pixel."""
    if not interacting or not levels:
        return 0
    target = max(size)
    for n, lv in enumerate(levels):
        if max(lv.shape) <= target:
            return n
    return len(levels) - 1


def render_bricked(source, scene, camera, size=(512, 512), *, memory=MEMORY, level: int = 0,
                   brick: int | None = None, value_range=None, device: str | None = None) -> Image:
    """Draw ``scene`` (its own ``volume`` ignored) with the volume of ``source`` read brick by brick.

    Parameters
    ----------
    source : path of an OME-Zarr / Zarr image, or a Volume (chunked or in memory)
    scene, camera, size, memory, brick, value_range, device :
        As in :func:`volumen.render.bricked.render_bricked` (``volumen.render`` on a chunked volume).
    level : int
        Pyramid level of a path (0: full resolution; :func:`pick_level`).

    Returns
    -------
    Image
        Equal (within float rounding) to the whole volume drawn at once with the same scene; ``stats`` as
        :func:`volumen.render.bricked.render_bricked`'s.
    """
    vol = open_volume(source, level)
    return bricked.render_bricked(scene.with_(volume=vol), camera, size, memory=memory, brick=brick,
                                  value_range=value_range, device=device)
