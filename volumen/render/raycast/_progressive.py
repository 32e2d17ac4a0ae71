"""The progressive path tracer of one (scene, camera, size): samples added step by step, denoised on request.

The kernels are :mod:`._pathtrace`'s; this module packs the frame (adding the majorant grid and the index ->
world gradient matrix the path tracer reads), runs the tiles on every thread (``volumen.jit.run_claiming``) and
turns the running sums into an :class:`~volumen.core.Image`, through Intel Open Image Denoise (:mod:`._denoise`)
fed the first events' expected albedo and normal (:mod:`._features`, noise-free) when denoising.
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from ...jit import run_claiming
from .._slab import slabbed
from ._denoise import denoise
from ._majorant import MAJ_BLOCK, majorant_grid
from ._medium import depth_bound, label_scale
from ._pack import pack_frame
from ._pathtrace import NACC, NFEAT, trace_tiles
from ._tiles import TILE, tile_order

__all__ = ["PathTracer"]


def _gradient_matrix(volume) -> np.ndarray:
    """(4, 3): rows 0-2 take an index-space gradient to world space (the inverse transpose of the affine's 3x3)."""
    m = np.zeros((4, 3))
    m[:3] = np.linalg.inv(np.asarray(volume.affine, float)[:3, :3]).T
    return m


def _majorants(f) -> np.ndarray:
    """The frame's majorant grid (1/mm, ``_majorant.majorant_grid``), kept with the volume per table.

    With a label map, the label rows drawn with the scan's table (textured) are bounded by the table's optical
    depth like the scan (the grid), the solid ones by their own everywhere (``_medium.depth_bound``): a label
    map drawn with the scan's own table tracks exactly as the scan alone."""
    a, st = f.arrays, f.settings
    scale = st.extinction_scale / st.ds0
    solid = 0.0
    if st.nlabels > 0:
        solid_rows = a.label_lut[a.label_lut[:, 4] == 0.0]
        solid = depth_bound(a.extinction[:1] * 0.0, solid_rows, label_scale(st.ds, st.ds0, st.extinction_scale),
                            len(solid_rows)) if len(solid_rows) else 0.0
    bmin, bmax = f.prep.blocks(MAJ_BLOCK)
    key = ("majorants", MAJ_BLOCK, a.extinction.tobytes(), scale, solid)
    return f.prep.memo(key, lambda: np.maximum(majorant_grid(a.extinction, bmin, bmax, scale),
                                               np.float32(solid * scale)))


class PathTracer:
    """A progressive path tracer of one (scene, camera, size): each :meth:`step` adds samples per pixel.

    Parameters
    ----------
    scene : Scene
        Mode ``composite``; its shading settings give the medium (``sigma_a``, ``sigma_s``, ``phase_g``),
        ``diffuse`` (light scale), ``pt_bounces``, ``shadow_offset`` and ``pathtrace.denoise``; its environment
        the light around (``ambient``: the uniform one's radiance); ``sampling.seed`` seeds the random numbers.
        The shading mode itself is ignored.
    camera : Camera
    size : (width, height), pixels

    Attributes
    ----------
    spp : int
        Samples per pixel accumulated so far.
    coverage : (H, W) float32
        The pixels' opacity, ``1 - exp(-optical depth)`` along their view rays (the pictures' alpha).
    features : (H, W, 6) float32
        The denoiser's auxiliary pictures: the view rays' first events' expected albedo (0-2) and normal (3-5),
        premultiplied by the opacity (:func:`._features.view_features`).
    display : Display
        The scene's display for path-traced pictures (the images carry it).
    """

    #: the ``stats["backend"]`` of the images
    backend = "cpu"

    def __init__(self, scene, camera, size):
        if scene.mode != "composite":
            raise ValueError(f"path tracing needs mode 'composite', got {scene.mode!r}")
        scene = replace(slabbed(scene), shading=replace(scene.shading, mode="pathtrace"))
        f = pack_frame(scene, camera, size)
        arrays = f.arrays._replace(majorant=_majorants(f), gradient_matrix=_gradient_matrix(scene.volume))
        self.frame = replace(f, arrays=arrays, settings=f.settings._replace(majorant_block=MAJ_BLOCK))
        w, h = self.frame.size
        self.acc = np.zeros((h, w, NACC), np.float64)
        self.coverage = np.zeros((h, w), np.float32)
        self.features = np.zeros((h, w, NFEAT), np.float32)
        self.spp = 0
        self.seconds = 0.0
        self.denoise = scene.shading.pathtrace.denoise
        self.display = scene.display.resolved("pathtrace")

    def _accumulate(self, s0: int, s1: int) -> None:
        """Add samples ``s0 .. s1 - 1`` of every pixel into ``self.acc`` (and, from 0, the coverage)."""
        f = self.frame
        w, h = f.size
        order = tile_order(w, h)
        run_claiming(trace_tiles, order.shape[0], order, TILE, (s0, s1), f.arrays, f.settings,
                     (self.acc, self.coverage, self.features))

    def reset(self) -> None:
        """Forget the accumulated samples."""
        self.acc[...] = 0.0
        self.spp = 0
        self.seconds = 0.0

    def add(self, n_samples: int = 1) -> float:
        """Add ``n_samples`` samples per pixel (no picture made); returns the seconds it took."""
        n = int(n_samples)
        if n < 1:
            raise ValueError(f"n_samples must be >= 1, got {n_samples!r}")
        t = time.perf_counter()
        self._accumulate(self.spp, self.spp + n)
        dt = time.perf_counter() - t
        self.spp += n
        self.seconds += dt
        return dt

    def step(self, n_samples: int = 1):
        """Add ``n_samples`` samples per pixel; returns :meth:`image` (denoised when ``pathtrace.denoise``)."""
        return self.image(kernel_seconds=self.add(n_samples))

    def image(self, denoised: bool | None = None, kernel_seconds: float = 0.0):
        """The current :class:`~volumen.core.Image`.

        ``rgba``: the running mean of the radiance (premultiplied, linear; above 1 where the medium is
        brighter than white, unless the display is ``linear``, which saturates it at the opacity: the picture
        without a tone curve), denoised by Open Image Denoise when ``denoised`` (default: ``pathtrace.denoise``),
        alpha :attr:`coverage`; ``depth``: the mean distance (mm) of the first scattering event along the view
        ray (inf where none happened); ``stats["spp"]``, ``stats["denoised"]``,
        ``stats["timings"]`` (``kernel`` the seconds of the last step, ``denoise``).
        """
        from ...core import Image

        if self.spp < 1:
            raise ValueError("no samples yet: call step() first")
        f = self.frame
        w, h = f.size
        denoised = self.denoise if denoised is None else bool(denoised)
        mean = self.acc / self.spp
        rgb = np.maximum(mean[..., :3], 0.0)
        alpha = self.coverage.astype(np.float64)
        t = time.perf_counter()
        if denoised:  # no path meets the medium where alpha is 0: the denoiser's filter must not bleed into it
            rgb = denoise(rgb, self.features[..., :3], self.features[..., 3:], covered=alpha > 0)
        t_denoise = time.perf_counter() - t
        rgb[alpha == 0] = 0.0  # premultiplied: a path of a jittered ray may meet what the 3x3 coverage rays miss
        if not f.settings.hdr:
            rgb = np.minimum(np.clip(rgb, 0.0, 1.0), alpha[..., None])
        rgba = np.concatenate([rgb, alpha[..., None]], axis=-1).astype(np.float32)
        hits = self.acc[..., 3]
        with np.errstate(invalid="ignore", divide="ignore"):
            depth = np.where(hits > 0, self.acc[..., 4] / np.maximum(hits, 1), np.inf).astype(np.float32)
        timings = dict(f.timings, kernel=kernel_seconds, total=self.seconds, denoise=t_denoise)
        stats = {"timings": timings, "spp": self.spp, "samples": self.spp * w * h, "rays": w * h,
                 "rays_hit": int(np.count_nonzero(hits)), "backend": self.backend, "mode": "composite",
                 "shading": "pathtrace", "step_mm": f.ds, "reference_step_mm": f.ds0, "denoised": denoised}
        return Image(rgba=rgba, depth=depth, stats=stats, display=self.display)
