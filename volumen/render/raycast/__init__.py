"""CPU ray casting (Numba), and the public interface the CUDA target builds on.

One marching skeleton (``_march``) specialised per mode (``_composite``,
``_project``, ``_iso``) and per shading model (``_shade``) through tags
(``_pieces``); the frame's arrays and settings declared once (``_frame``).
Other modules: ``_ray`` (a view ray), ``_geometry`` (rays, clipping),
``_sample`` (reconstruction), ``_labelled`` (label-aware classification), ``_medium`` (what light paths
cross), ``_shadow`` (direct shadow rays), ``_lightvol``
and ``_lightsweep`` (illumination volumes), ``_scatter`` (the scattering
medium), ``_pathtrace`` (path-tracing kernels: ``_majorant`` tracking, ``_sobol`` random numbers,
``_environment`` the environment light), ``_progressive`` (the progressive path tracer, ``_denoise``;
``_features`` the denoiser's noise-free albedo and normal),
``_tiles`` (the tiles of a picture), ``_precompute`` and
``_cache`` (per-volume arrays), ``_tables`` (transfer-function tables),
``_params`` (illumination-volume layout), ``_pack`` (scene -> Frame), ``_cpu``
(the CPU driver).

The CUDA backend (:mod:`volumen.render.cuda`) uses the names below only.
"""

from ...jit import inlining_active
from ._cache import clear_cache, prepare, prepared_volumes
from ._cpu import TILE, frame_image, render_cpu, render_part
from ._frame import FAR, PER_VOLUME, Arrays, Frame, Outputs, Settings
from ._geometry import G_BOX, G_INV, pack_geometry, to_index
from ._iso import iso_refine
from ._lightsweep import (
    LatticeRay,
    Sweep,
    lattice_frame,
    lattice_ray,
    lattice_slice,
    lattice_step,
    lattice_transmittance_of,
    sweep_medium,
)
from ._lightvol import plan_lattice
from ._march import trace_pixel
from ._medium import Medium
from ._pack import pack_frame, scene_lights
from ._params import (
    DIRECT,
    LATTICE,
    LV_AXA,
    LV_AXB,
    LV_AXC,
    LV_KIND,
    LV_NK,
    LV_NU,
    LV_NV,
    LV_OFF,
    NMETA,
)
from ._pathtrace import NACC, coverage_pixel, trace_path
from ._pieces import for_cuda
from ._progressive import PathTracer
from ._sample import sample_value

__all__ = ["render_cpu", "render_part", "TILE", "clear_cache",
           "PathTracer", "G_BOX", "G_INV", "pack_geometry", "to_index", "sample_value",
           "iso_refine", "prepare", "prepared_volumes", "pack_frame", "scene_lights", "frame_image", "Frame", "Arrays",
           "Settings",
           "Outputs", "PER_VOLUME", "FAR", "trace_pixel", "trace_path", "coverage_pixel", "NACC",
           "lattice_frame", "lattice_ray", "LatticeRay",
           "lattice_slice", "lattice_step", "lattice_transmittance_of", "plan_lattice", "Sweep", "DIRECT", "LATTICE",
           "LV_AXA", "LV_AXB", "LV_AXC", "LV_KIND", "LV_NK", "LV_NU", "LV_NV", "LV_OFF", "NMETA",
           "sweep_medium", "Medium", "inlining_active", "for_cuda"]
