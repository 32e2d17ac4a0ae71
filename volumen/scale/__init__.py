"""Beyond one machine's memory and one machine: bricked out-of-core rendering of chunked (OME-Zarr) volumes,
sort-last compositing, bricks and batches of studies on Dask distributed.

The bricked drawing itself is the renderer's (``volumen.render.bricked``: bricks, sort-last compositing, the
loop through the volume's bounded chunk cache), which ``volumen.render`` runs on a chunked volume; the chunk
cache is ``volumen.io``'s. Modules here: ``_pyramid_levels`` (a path's pyramid level opened and drawn brick by
brick, the level an interactive view picks), ``_distributed`` (bricks on Dask workers), ``_batch`` (a
manifest of studies on a Dask cluster), ``_synthetic`` (big test volumes written plane by plane), ``_interactive``
(a coarse level while the user interacts).
"""

from ..io import ChunkCache
from ..render.bricked import Partial, combine, parse_bytes
from ._batch import read_manifest, run_batch, run_study
from ._distributed import render_distributed
from ._interactive import render_view
from ._pyramid_levels import open_volume, pick_level, render_bricked
from ._synthetic import SyntheticBlob, write_synthetic

__all__ = ["render_bricked", "render_distributed", "run_batch", "run_study", "read_manifest", "ChunkCache",
           "pick_level", "open_volume", "parse_bytes", "Partial", "combine", "SyntheticBlob", "write_synthetic",
           "render_view"]
