"""One volume on many workers: bricks drawn on Dask workers, composited sort-last by a tree of "over".

The client plans the bricks (front to back, empty ones dropped from the
stored per-chunk ranges) and submits one task per brick; each worker opens
the OME-Zarr itself and reads only its brick's chunks. Neighbouring partials
are then combined pairwise, level by level, on the workers: the operators are
associative, so any grouping that keeps the order gives the single-process
picture (``volumen.render.bricked.render_bricked``) -- without early ray
termination (``Sampling.early_termination = 1``): bricks drawn at once cannot
carry the opacity in front of them, so each ray runs through every brick.
"""

from __future__ import annotations

import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from ..core import Image
from ..render.bricked import (
    brick_visible,
    chunk_range,
    combine,
    draw_brick,
    empty_partial,
    plan,
    source_of,
    whole_geometry,
)
from ._pyramid_levels import open_volume

__all__ = ["render_distributed"]


def _draw_on_worker(path, level, b, scene, camera, size, vr):
    src = source_of(open_volume(path, level))
    w, h = size
    return draw_brick(src, src.data, b, scene, camera, size, vr, whole_geometry(src, scene),
                      np.zeros((h, w), np.float32))


def _combine_on_worker(front, back, mode):
    if front is None:
        return back
    if back is None:
        return front
    return combine(front, back, mode)


def render_distributed(client, source, scene, camera, size=(512, 512), *, level: int = 0, brick: int | None = None,
                       value_range=None) -> Image:
    """Draw the OME-Zarr ``source`` (a path every worker can read) brick by brick on ``client``'s workers.

    Same modes and result as :func:`~volumen.scale.render_bricked`; ``stats``: ``bricks``, ``bricks_drawn``,
    ``tasks``.
    """
    t0 = time.perf_counter()
    path = str(Path(source))
    src, vr, bricks = plan(open_volume(path, level), scene, camera, brick=brick, value_range=value_range)
    light = replace(scene, volume=None)  # the workers read the bricks themselves
    todo = [b for b in bricks if (r := chunk_range(src, b)) is None or brick_visible(scene, *r, vr)]
    futs = [client.submit(_draw_on_worker, path, level, b, light, camera, tuple(size), vr, pure=False) for b in todo]
    ntask = len(futs)
    while len(futs) > 1:
        nxt = [client.submit(_combine_on_worker, futs[i], futs[i + 1], scene.mode, pure=False)
               for i in range(0, len(futs) - 1, 2)]
        futs = nxt + ([futs[-1]] if len(futs) % 2 else [])
        ntask += len(nxt)
    w, h = (int(s) for s in size)
    part = futs[0].result() if futs else None
    part = empty_partial(w, h) if part is None else part
    stats = {"bricks": len(bricks), "bricks_drawn": len(todo), "tasks": ntask, "mode": scene.mode,
             "timings": {"total": time.perf_counter() - t0}}
    return Image(rgba=part.rgba, depth=part.depth, stats=stats, value=None if scene.mode == "composite" else part.value)
