"""Data and picture helpers of the raster tests (a uniquely named module; tests/ has no packages)."""

from __future__ import annotations

import numpy as np

from volumen.core import Volume


def blob_volume(n: int = 40) -> Volume:
    """A smooth CT-like ball (1000 HU inside, -1000 outside, tanh edge of 1.5 voxels) with an off-centre
    dense bead (+x, +z), unit spacing; asymmetric so mirrored pictures show."""
    z, y, x = np.mgrid[:n, :n, :n].astype(np.float64)
    c = (n - 1) / 2
    r = np.sqrt((x - c) ** 2 + (y - c) ** 2 + (z - c) ** 2)
    w = 0.5 * (1 - np.tanh((r - 0.32 * n) / 1.5))
    rb = np.sqrt((x - c - 0.3 * n) ** 2 + (y - c) ** 2 + (z - c - 0.25 * n) ** 2)
    w = np.maximum(w, 1.6 * 0.5 * (1 - np.tanh((rb - 0.1 * n) / 1.0)))
    # int16 (rounded HU) as CT is stored: the CPU pictures compared with run the phantoms' int16 kernels
    return Volume(np.rint(-1000 + 2000 * w).astype(np.int16), spacing=(1.0, 1.0, 1.0), modality="CT", units="HU")


def homogeneous_volume(n: int = 48) -> Volume:
    """A constant volume (100 HU everywhere, int16), unit spacing: a homogeneous slab filling its box."""
    return Volume(np.full((n, n, n), 100, np.int16), spacing=(1.0, 1.0, 1.0), modality="CT", units="HU")


def save_row(path, images, scale: float = 1.0) -> None:
    """Write pictures side by side (composed over black, each multiplied by ``scale``) as one PNG."""
    from PIL import Image as PILImage

    rows = [np.clip(im.rgba[..., :3] * scale, 0, 1) for im in images]
    h = max(r.shape[0] for r in rows)
    gap = np.full((h, 2, 3), 0.35)
    parts = []
    for r in rows:
        parts += [np.pad(r, ((0, h - r.shape[0]), (0, 0), (0, 0))), gap]
    PILImage.fromarray((np.concatenate(parts[:-1], axis=1) * 255).round().astype(np.uint8)).save(path)
