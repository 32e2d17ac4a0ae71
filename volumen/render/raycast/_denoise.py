"""Denoising of path-traced pictures: Intel Open Image Denoise (``pyoidn``, CPU) with auxiliary pictures.

The path tracer hands the running mean of its radiance (linear, high dynamic range) and of the first events'
albedo and normal; OIDN's ``RT`` filter (prefiltering the noisy auxiliary pictures itself, ``cleanAux`` off)
returns the denoised radiance.
"""

from __future__ import annotations

import numpy as np

__all__ = ["denoise", "DenoiserUnavailableError"]


class DenoiserUnavailableError(RuntimeError):
    """Intel Open Image Denoise (the Python package ``pyoidn``) cannot be loaded."""


def denoise(color: np.ndarray, albedo: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """Denoised ``color``: all three ``(H, W, 3)``, linear radiance >= 0, albedo in [0, 1], normals in [-1, 1]
    (world space); returns float64 radiance >= 0."""
    try:
        import pyoidn
    except ImportError as exc:  # a dependency of volumen: only a broken installation lacks it
        raise DenoiserUnavailableError(f"Open Image Denoise is not installed (pip install pyoidn): {exc}") from None
    c = np.ascontiguousarray(color, np.float32)
    out = pyoidn.denoise(c, np.ascontiguousarray(np.clip(albedo, 0.0, 1.0), np.float32),
                         np.ascontiguousarray(np.clip(normal, -1.0, 1.0), np.float32), hdr=True)
    return np.maximum(out.astype(np.float64), 0.0)
