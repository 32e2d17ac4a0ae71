"""Label maps on slice views: the label slice matching :func:`~volumen.core.slice_image`, outlines in colour.

numpy only; the command line and the app write the structure names beside the outlines.
"""

from __future__ import annotations

import numpy as np

from ._labels import LabelMap
from ._slices import slice_at
from ._volume import Volume

__all__ = ["label_slice", "outline_overlay"]


def label_slice(labels: LabelMap, plane, world=None, index=None, square_pixels: bool = True) -> np.ndarray:
    """The labels on the plane :func:`slice_image` shows for a scan on the same grid: ``(rows, cols)`` values,
    stretched to square pixels by repeating (nearest), like the scan's picture."""
    vol = Volume(labels.data, labels.spacing, labels.affine)
    img, (sr, sc) = slice_at(vol, plane, index=index, world=world)
    if square_pixels and not np.isclose(sr, sc, rtol=1e-3):
        base = min(sr, sc)
        rows = np.minimum((np.arange(int(round(img.shape[0] * sr / base))) * base / sr).astype(int), img.shape[0] - 1)
        cols = np.minimum((np.arange(int(round(img.shape[1] * sc / base))) * base / sc).astype(int), img.shape[1] - 1)
        img = img[rows][:, cols]
    return img


def outline_overlay(gray: np.ndarray, lab: np.ndarray, labels: LabelMap, values=None, width: int = 1,
                    fill: float = 0.0) -> np.ndarray:
    """``gray`` (uint8 (rows, cols)) as RGB with each structure's outline (pixels whose neighbour differs) in its
    colour, ``width`` pixels wide, and its inside tinted by ``fill`` (0..1). Returns uint8 ``(rows, cols, 3)``."""
    rgb = np.repeat(gray[..., None], 3, axis=2).astype(np.float32)
    shown = labels.values if values is None else list(values)
    for v in shown:
        m = lab == v
        if not m.any():
            continue
        edge = np.zeros_like(m)
        inner = m.copy()
        for _ in range(width):
            shrunk = inner.copy()
            shrunk[1:] &= inner[:-1]
            shrunk[:-1] &= inner[1:]
            shrunk[:, 1:] &= inner[:, :-1]
            shrunk[:, :-1] &= inner[:, 1:]
            edge |= inner & ~shrunk
            inner = shrunk
        col = np.asarray(labels.colors[v], np.float32) ** (1 / 2.2) * 255.0
        if fill > 0:
            rgb[m] = (1 - fill) * rgb[m] + fill * col
        rgb[edge] = col
    return np.clip(np.rint(rgb), 0, 255).astype(np.uint8)
