"""An abdomen-like phantom with ground-truth organ labels: :func:`organ_phantom`.

A body of soft tissue in fat, a spine, and five organs (liver, spleen, two kidneys, an
aorta with contrast), each an analytic ellipsoid or cylinder. The scan's values are HU
(with a little texture in the liver); the labels are the same shapes, so the label map
is exact ground truth for tests and the README picture.
"""

from __future__ import annotations

import numpy as np

from ..core import LabelMap, Volume

__all__ = ["organ_phantom", "ORGANS"]

#: RAS: +x is the patient's right (the liver), +y anterior, +z superior
#: name -> (label value, HU, linear rgb, centre (x, y, z) in units of the half-size, radii (x, y, z) likewise)
ORGANS = {
    "liver": (1, 60.0, (0.75, 0.30, 0.22), (0.35, 0.05, 0.15), (0.38, 0.42, 0.40)),
    "spleen": (2, 50.0, (0.55, 0.25, 0.60), (-0.50, -0.15, 0.25), (0.16, 0.22, 0.25)),
    "kidney_left": (3, 35.0, (0.85, 0.65, 0.25), (-0.38, -0.38, -0.25), (0.13, 0.13, 0.25)),
    "kidney_right": (4, 35.0, (0.85, 0.65, 0.25), (0.38, -0.38, -0.25), (0.13, 0.13, 0.25)),
    "aorta": (5, 250.0, (0.90, 0.15, 0.15), (0.0, -0.30, 0.0), (0.07, 0.07, 2.0)),
}


def _grid(n: int):
    c = (np.arange(n) - (n - 1) / 2.0) / (n / 2.0)
    return np.meshgrid(c, c, c, indexing="ij")  # z, y, x in [-1, 1]


def organ_phantom(size: int = 96, spacing: float = 2.0, seed: int = 0) -> tuple[Volume, LabelMap]:
    """A CT-like abdomen (int16 HU, ``size`` voxels a side of ``spacing`` mm) and its organ labels.

    Returns
    -------
    (Volume, LabelMap)
        The scan and the exact labels on the same grid (names and colours of :data:`ORGANS`).
    """
    z, y, x = _grid(size)
    rng = np.random.default_rng(seed)
    data = np.full(z.shape, -1000.0, np.float32)
    body = (x / 0.85) ** 2 + (y / 0.65) ** 2 <= 1.0
    data[body] = -100.0  # fat
    data[(x / 0.80) ** 2 + (y / 0.60) ** 2 <= 1.0] = 30.0  # muscle / soft tissue
    data[(x / 0.68) ** 2 + (y / 0.50) ** 2 <= 1.0] = -80.0  # abdominal fat
    data[(x / 0.10) ** 2 + ((y + 0.52) / 0.10) ** 2 <= 1.0] = 700.0  # vertebrae
    labels = np.zeros(z.shape, np.uint8)
    for value, hu, _, c, r in ORGANS.values():
        m = ((x - c[0]) / r[0]) ** 2 + ((y - c[1]) / r[1]) ** 2 + ((z - c[2]) / r[2]) ** 2 <= 1.0
        m &= body
        data[m] = hu
        labels[m] = value
    liver = labels == ORGANS["liver"][0]
    data[liver] += 12.0 * np.sin(9 * x[liver]) * np.sin(7 * y[liver]) * np.sin(8 * z[liver])
    data[body] += rng.normal(0.0, 6.0, int(body.sum())).astype(np.float32)
    offset = -(size - 1) / 2.0 * spacing
    affine = np.diag([spacing, spacing, spacing, 1.0])
    affine[:3, 3] = offset
    vol = Volume(np.round(data).astype(np.int16), (spacing,) * 3, affine, modality="CT", units="HU",
                 name="organ phantom")
    names = {v: n for n, (v, *_) in ORGANS.items()}
    colors = {v: col for v, _, col, *_ in ORGANS.values()}
    return vol, LabelMap(labels, (spacing,) * 3, affine.copy(), names, colors, {"source": "organ phantom"})
