"""Beyond one machine's memory and one machine: bricked out-of-core rendering of chunked (OME-Zarr) volumes,
sort-last compositing, bricks and batches of studies on Dask distributed.

Modules: ``_bricks`` (cutting a volume into bricks drawn apart, visibility
order), ``_composite`` (the associative over / max / min), ``_outofcore``
(bricks through a bounded chunk cache), ``_distributed`` (bricks on Dask
workers), ``_batch`` (a manifest of studies on a Dask cluster), ``_synthetic``
(big test volumes written plane by plane), ``_view`` (a coarse level while the user interacts).
"""

from ._batch import read_manifest, run_batch, run_study
from ._composite import Partial, combine
from ._distributed import render_distributed
from ._outofcore import ChunkCache, parse_bytes, pick_level, render_bricked
from ._synthetic import SyntheticBlob, write_synthetic
from ._view import render_view

__all__ = ["render_bricked", "render_distributed", "run_batch", "run_study", "read_manifest", "ChunkCache",
           "pick_level", "parse_bytes", "Partial", "combine", "SyntheticBlob", "write_synthetic",
           "render_view"]
