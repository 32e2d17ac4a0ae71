"""Denoising of path-traced pictures: Intel Open Image Denoise (``pyoidn``, CPU) with auxiliary pictures.

The path tracer hands the running mean of its radiance (linear, high dynamic range: ``hdr``, OIDN's own exposure
estimate) and its view rays' first events' expected albedo and normal, computed by a deterministic march
(:mod:`._features`), so noise-free: OIDN's ``RT`` filter takes them as they are (``cleanAux``) and returns the
denoised radiance.

The denoiser is not unbiased: it takes the rare bright samples for noise and drops their energy (or lends
energy to dark regions), so its picture is darker or brighter than the samples' mean by about 1 % (measured by
``volumen bench pathtrace``). The samples' mean is unbiased, and its noise averages out over many pixels, so
the denoised picture is scaled to keep the samples' local mean: ``out * G(color) / G(out)``, ``G`` a Gaussian of
:data:`ENERGY_SIGMA` pixels per channel, the ratio held in [1/2, 2] (where the denoiser removed nearly all of a
region's energy, it is not made up).
"""

from __future__ import annotations

import numpy as np

__all__ = ["denoise", "keep_energy", "DenoiserUnavailableError", "ENERGY_SIGMA"]

#: standard deviation (pixels) of the window whose mean radiance the denoised picture keeps
ENERGY_SIGMA = 8.0


class DenoiserUnavailableError(RuntimeError):
    """Intel Open Image Denoise (the Python package ``pyoidn``) cannot be loaded."""


def keep_energy(out: np.ndarray, color: np.ndarray, sigma: float = ENERGY_SIGMA) -> np.ndarray:
    """``out`` (H, W, 3) scaled so its mean over a Gaussian window of ``sigma`` pixels is ``color``'s."""
    from scipy.ndimage import gaussian_filter

    num = gaussian_filter(color, (sigma, sigma, 0.0))
    den = gaussian_filter(out, (sigma, sigma, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(den > 1e-12, num / den, 1.0)
    return out * np.clip(ratio, 0.5, 2.0)


def denoise(color: np.ndarray, albedo: np.ndarray, normal: np.ndarray, covered: np.ndarray | None = None) -> np.ndarray:
    """Denoised ``color``: all three ``(H, W, 3)``, linear radiance >= 0, albedo in [0, 1], normals in [-1, 1]
    (world space), the auxiliary pictures noise-free; returns float64 radiance >= 0, 0 outside ``covered``
    ((H, W) bool, where the medium is: the filter must not bleed into the rest), with ``color``'s local mean
    (:func:`keep_energy`)."""
    try:
        import pyoidn
    except ImportError as exc:  # a dependency of volumen: only a broken installation lacks it
        raise DenoiserUnavailableError(f"Open Image Denoise is not installed (pip install pyoidn): {exc}") from None
    c = np.ascontiguousarray(color, np.float32)
    out = pyoidn.denoise(c, np.ascontiguousarray(np.clip(albedo, 0.0, 1.0), np.float32),
                         np.ascontiguousarray(np.clip(normal, -1.0, 1.0), np.float32), hdr=True, clean_aux=True)
    out = np.maximum(out.astype(np.float64), 0.0)
    if covered is not None:
        out[~covered] = 0.0
    return keep_energy(out, np.asarray(color, np.float64))
