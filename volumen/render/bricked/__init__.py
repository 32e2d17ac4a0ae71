"""Bricked ray casting: a volume too big for memory (a chunked OME-Zarr level) drawn brick by brick, composited
sort-last (docs/design.md section 7).

``volumen.render`` draws a chunked volume with :func:`render_bricked`; ``volumen.scale`` adds the storage side
(opening OME-Zarr paths and pyramid levels, the interactive level choice, bricks on Dask workers).

Modules: ``_bricks`` (cutting a volume into bricks drawn apart, visibility order), ``_composite`` (the
associative over / max / min of partial pictures), ``_outofcore`` (the bricks through the volume's bounded
chunk cache, front to back). Importing this package loads Numba (the ray caster's kernels).
"""

from ._bricks import Brick, brick_visible
from ._composite import MODES, Partial, combine, empty_partial
from ._outofcore import (
    BRICK,
    MEMORY,
    chunk_range,
    default_brick,
    draw_brick,
    parse_bytes,
    plan,
    render_bricked,
    source_of,
    whole_geometry,
)

__all__ = ["render_bricked", "plan", "draw_brick", "whole_geometry", "source_of", "chunk_range", "default_brick",
           "parse_bytes", "BRICK", "MEMORY", "MODES", "Brick", "brick_visible", "Partial", "combine",
           "empty_partial"]
