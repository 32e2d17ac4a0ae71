"""What one frame hands the kernels, declared once: the per-frame arrays, the scalar settings, the outputs.

Every kernel (CPU and CUDA, ray casting and path tracing) takes the three
records below as whole arguments -- ``a`` (:class:`Arrays`), ``s``
(:class:`Settings`), ``out`` (:class:`Outputs`) -- and reads fields by name
(``a.vol``, ``s.ds``). Numba compiles a NamedTuple argument as a struct, so
there are no positional lists to keep in step and no index constants: the
field lists below generate the CPU driver's arguments, the CUDA uploads
(:meth:`Frame.device_arrays` sends every field of :class:`Arrays`, and keeps
the :data:`PER_VOLUME` ones on the device while they are the same object) and
the compile cache keys (Numba keys compiled code by these records' types).

Adding a per-frame setting touches its declaration and its use only: a field
here, with its default (``Settings``) -- set from the scene in ``_pack`` when
the default does not do -- and ``s.<name>`` where a kernel reads it
(``tests/render/test_layout.py`` checks that every array reaches the device and that a setting needs
only its declaration and its use).
Compile-time choices (the mode and the shading model) are not settings but
tags (:mod:`._pieces`), which pick the pieces a kernel is built from.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np

from ._pieces import ScanOnly, Trilinear

__all__ = ["Arrays", "Settings", "Outputs", "Frame", "PER_VOLUME", "FAR"]

#: "infinitely far" inside the kernels, which are compiled with fastmath (no inf/NaN semantics);
#: ``trace_pixel`` turns depth >= FAR into inf and value >= FAR into NaN when it writes them.
FAR = 1e30


class Arrays(NamedTuple):
    """The per-frame arrays (see the modules named for their layouts)."""

    cam: np.ndarray  #: packed camera, float64 (18,) (``_geometry.pack_camera``)
    geo: np.ndarray  #: packed region: world->index affine, index and world crop boxes (``_geometry``)
    planes: np.ndarray  #: clip planes (n, 6): point, unit normal
    vol: np.ndarray  #: int16 samples [z, y, x]: the data itself or an int16 copy (``_precompute.int16_samples``)
    gradient_matrix: np.ndarray  #: gradient matrix and 1 / gmax (4, 3) float64 (``_precompute.normal_params``)
    normal_codes: np.ndarray  #: normal direction codes, a pool of bricks uint16 (``_normals``), (1, 1, 1) when unused
    normal_slots: np.ndarray  #: each brick's slot in ``normal_codes`` int32 (``_normals``), (1, 1, 1) when unused
    gradient_codes: np.ndarray  #: gradient-magnitude code per voxel [z, y, x] uint8, (1, 1, 1) when unused
    normal_dirs: np.ndarray  #: direction code -> unit vector, packed in a uint32 (``_normals.DIRS``)
    lut: np.ndarray  #: colour / opacity table (NLUT, 4) (``_tables``)
    preintegrated: np.ndarray  #: pre-integrated table (NPRE, NPRE, 4), (1, 1, 4) when unused
    gradient_lut: np.ndarray  #: gradient-opacity factor per magnitude code (128,)
    skip_flags: np.ndarray  #: skip side per ray octant and block (8, gz, gy, gx) uint8 (``_octants``); (1, 1, 1, 1) off
    bmin: np.ndarray  #: block minima (normalized units)
    bmax: np.ndarray  #: block maxima
    coarse_flags: np.ndarray  #: adaptive sampling: octant sides of coarse blocks (``_tables``); (1, 1, 1, 1) off
    cells: np.ndarray  #: a bit per cell that can hold a visible sample (``_cells``); (1, 1, 1) off
    lights: np.ndarray  #: packed lights (n, NLCOL) (``_shade``)
    light_meta: np.ndarray  #: illumination-volume meta rows (n, NMETA) (``_lightvol``)
    light_data: np.ndarray  #: illumination-volume buffer (float32)
    extinction: np.ndarray  #: optical depth per reference step of each table entry (NLUT,)
    label_map: np.ndarray  #: label map [z, y, x] on the volume's grid (``_labelled``), (1, 1, 1) when unused
    label_lut: np.ndarray  #: per label value (r, g, b, opacity, textured) (n, 5) (``_labelled``)
    rgb: np.ndarray  #: colour volume's RGB [z, y, x, 3] uint8 (``_color``), (1, 1, 1, 3) for a scalar volume
    whole: np.ndarray  #: packed region whose sample grid the rays follow: ``geo`` itself, or a part's whole (``_ray``)
    carry: np.ndarray  #: a part's opacity carried in per pixel (H, W) float32 (``_ray``), (1, 1) when unused
    env: np.ndarray  #: environment radiance map (He, We, 3) float32 (``_environment``), (2, 2, 3) when uniform
    env_basis: np.ndarray  #: the map frame's axes in world space (3, 3) float64
    env_cdf: np.ndarray  #: the map's importance-sampling tables (He + 1, We + 1) float64
    env_sh: np.ndarray  #: the map's SH coefficients to order 2 (9, 3) float64: the ray-cast models' ambient term
    #: path tracing: majorant extinction (1/mm) per block of ``majorant_block^3`` voxels (``_majorant``)
    majorant: np.ndarray


#: fields of :class:`Arrays` that belong to the volume, or to it and a transfer function (cached objects, never
#: changed in place): a device keeps its copy while the object is the same, without comparing contents (``skip_flags``
#: is 4.7 MB at 366 x 303 x 336: comparing it took 1 ms of a 7.6 ms CUDA frame)
PER_VOLUME = ("vol", "gradient_matrix", "normal_codes", "normal_slots", "gradient_codes", "normal_dirs", "bmin",
              "bmax", "skip_flags", "label_map", "rgb", "cells")


class Settings(NamedTuple):
    """The scalar settings of a frame (lengths in mm, values in the table's normalized units)."""

    ds: float = 1.0  #: sample step
    ds0: float = 1.0  #: reference step (smallest voxel spacing) the opacities are defined for
    early_termination: float = 0.98  #: early ray termination opacity
    ambient: float = 0.15  #: ambient (scattering: environment radiance)
    diffuse: float = 0.65  #: diffuse (scattering: light scale)
    specular: float = 0.2  #: specular
    shininess: float = 20.0  #: specular exponent
    #: stored sample -> table units: ``(v - sample_offset) * sample_scale`` (``Arrays.vol`` may be raw data)
    sample_offset: float = 0.0
    sample_scale: float = 1.0
    value_min: float = 0.0  #: data value of normalized 0
    value_scale: float = 1.0  #: data units per normalized unit
    iso_value: float = 0.0  #: isosurface threshold (normalized)
    iso_red: float = 1.0  #: isosurface colour
    iso_green: float = 1.0
    iso_blue: float = 1.0
    pre_scale: float = 1.0  #: normalized value -> pre-integrated table index
    shadow_offset: float = 2.0  #: light paths start this far off the sample (no self-shadowing)
    shadow_step: float = 1.0  #: direct shadow-ray step
    extinction_scale: float = 1.0  #: extinction scale: sigma_t = extinction_scale * (-ln(1 - alpha)) / ds0
    albedo: float = 1.0  #: single-scattering albedo
    phase_g: float = 0.0  #: Henyey-Greenstein anisotropy
    nearest: bool = False  #: nearest-neighbour instead of trilinear reconstruction
    recon: Any = Trilinear()  #: reconstruction tag (``_pieces``): Trilinear() (or nearest), or BSpline() (``_bspline``)
    jitter: bool = False  #: jitter each ray's first sample
    lattice: bool = False  #: samples at t = (m + jitter) ds from the ray's origin, not from its entry (``_ray``)
    seed: int = 0  #: jitter / path-tracing seed
    skip: bool = False  #: empty-space skipping
    block: int = 4  #: block size of the skipping grids (voxels)
    stride: int = 1  #: adaptive sampling: most grid steps one sample stands for in ``Arrays.coarse_flags`` blocks
    cells: bool = False  #: pass over the samples in the cells ``Arrays.cells`` marks transparent (``_cells``)
    gradient_opacity: bool = False  #: gradient-magnitude opacity modulation
    sobel: bool = False  #: normals from the 3x3x3 Sobel operator instead of central differences
    nlights: int = 0  #: lights in use (rows of ``Arrays.lights``)
    nplanes: int = 0  #: clip planes in use
    bounces: int = 1  #: path tracing: most scattering events per path
    nlabels: int = 0  #: label-aware classification (rows of ``Arrays.label_lut``; 0: off)
    labels: Any = ScanOnly()  #: label tag (``_pieces``): ``WithLabels()`` exactly when nlabels > 0
    solid_labels: bool = False  #: some shown structure is solid (an opacity of its own, ``_labelled.solid_rows``)
    color: bool = False  #: colour volume: emission colour from ``Arrays.rgb``, not the table (``_color``)
    part: bool = False  #: draw the samples of ``Arrays.whole``'s grid inside ``geo`` only (a brick, ``_ray``)
    env_mode: int = 0  #: 0: ambient radiance ``ambient`` (uniform environment); 1: ``Arrays.env`` (``_environment``)
    env_power: float = 0.0  #: path tracing: weight of the environment against the lights in light selection
    majorant_block: int = 8  #: path tracing: block edge of ``Arrays.majorant`` (voxels)
    projection: int = 0  #: the projection (``_pieces.PROJECTIONS``): 0 maximum, 1 minimum, 2 mean
    hdr: bool = False  #: composite colour left unclipped (high dynamic range, for a tone curve), else at most 1


class Outputs(NamedTuple):
    """What a ray-casting kernel writes per pixel."""

    rgba: Any   #: (H, W, 4) float32 premultiplied
    depth: Any  #: (H, W) float32 mm, inf where nothing was hit (FAR inside the kernel until ``trace_pixel`` ends)
    value: Any  #: (H, W) float32 projected value (data units), NaN where none (likewise)
    nsamp: Any  #: (H, W) int32 samples taken

    @classmethod
    def empty(cls, w: int, h: int, alloc=np.empty) -> Outputs:
        return cls(alloc((h, w, 4), np.float32), alloc((h, w), np.float32), alloc((h, w), np.float32),
                   alloc((h, w), np.int32))

    @classmethod
    def cleared(cls, w: int, h: int) -> Outputs:
        """Outputs of pixels no ray is traced for, as the drivers hand them out: transparent, depth inf, value
        NaN, no samples."""
        return cls(np.zeros((h, w, 4), np.float32), np.full((h, w), np.inf, np.float32),
                   np.full((h, w), np.nan, np.float32), np.zeros((h, w), np.int32))


@dataclass(frozen=True)
class Frame:
    """One packed frame: the kernels' records, the compile-time tags, and what the drivers report."""

    arrays: Arrays
    settings: Settings
    mode: Any            #: mode tag (``_pieces``)
    light: Any           #: shading-model tag (``_pieces``)
    size: tuple[int, int]
    prep: Any            #: the volume's cached precomputations (``_cache.Prepared``)
    light_volumes_built: int = 0
    timings: dict = field(default_factory=dict)

    @property
    def ds(self) -> float:
        return self.settings.ds

    @property
    def ds0(self) -> float:
        return self.settings.ds0

    def device_arrays(self, put) -> Arrays:
        """:class:`Arrays` with each field replaced by ``put(name, array, same_object)`` (a device copy)."""
        return Arrays(*(put(n, x, n in PER_VOLUME) for n, x in zip(Arrays._fields, self.arrays, strict=True)))
