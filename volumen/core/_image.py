"""The result of a renderer: premultiplied linear RGBA, depth and statistics (docs/design.md section 2)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from ._repr import picture

__all__ = ["Image"]


def _srgb_encode(x: np.ndarray) -> np.ndarray:
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(np.maximum(x, 0.0031308), 1 / 2.4) - 0.055)


@dataclass(eq=False)
class Image:
    """A rendered picture.

    Parameters
    ----------
    rgba : (H, W, 4) float32
        Colour premultiplied by alpha, linear, in [0, 1]. Row 0 is the top.
    depth : (H, W) float32, mm
        Distance along the view ray from the eye (orthographic: from the
        image plane through the camera position) to what the pixel shows;
        ``inf`` where nothing was hit. Each mode documents its choice
        (``volumen.render``).
    stats : dict
        ``timings`` (dict of seconds), ``samples`` (int, samples taken),
        ``rays`` (int), and whatever else the renderer reports.
    value : (H, W) float32 or None
        For projection modes (mip, minip, average): the projected data value,
        in the data's units, NaN where no ray met the volume.
    """

    rgba: np.ndarray
    depth: np.ndarray
    stats: dict[str, Any] = field(default_factory=dict)
    value: np.ndarray | None = None

    def __post_init__(self) -> None:
        self.rgba = np.asarray(self.rgba, dtype=np.float32)
        if self.rgba.ndim != 3 or self.rgba.shape[2] != 4:
            raise ValueError(f"rgba must be (H, W, 4), got {self.rgba.shape}")
        self.depth = np.asarray(self.depth, dtype=np.float32)
        if self.depth.shape != self.rgba.shape[:2]:
            raise ValueError(f"depth must be (H, W) = {self.rgba.shape[:2]}, got {self.depth.shape}")

    @property
    def size(self) -> tuple[int, int]:
        """``(width, height)`` in pixels."""
        return self.rgba.shape[1], self.rgba.shape[0]

    @property
    def alpha(self) -> np.ndarray:
        """(H, W) float32 opacity."""
        return self.rgba[..., 3]

    def to_uint8(self, background: tuple[float, float, float] | None = (0.0, 0.0, 0.0),
                 encoding: Literal["linear", "srgb"] = "linear", gain: float = 1.0) -> np.ndarray:
        """8-bit picture for display or files.

        Parameters
        ----------
        background : (3,) float in [0, 1], linear RGB, or None
            Composed under the image (``rgb + (1 - alpha) * background``),
            giving an ``(H, W, 3)`` uint8 array. None returns ``(H, W, 4)``
            with straight (un-premultiplied) alpha.
        encoding : {"linear", "srgb"}
            ``linear`` (default) writes the linear values as they are
            (``round(255 * v)``), as VTK and most volume renderers do, so
            transfer-function colours appear as authored; ``srgb`` applies the
            sRGB transfer curve (brighter mid-tones, physically displayed
            linear light).
        gain : float
            Display brightness: the colour (not the opacity) is scaled by
            ``gain`` before composing (the application's brightness slider).
        """
        if encoding not in ("linear", "srgb"):
            raise ValueError(f"encoding must be 'linear' or 'srgb', got {encoding!r}")
        rgb = self.rgba[..., :3].astype(np.float64) * float(gain)
        a = self.rgba[..., 3:4].astype(np.float64)
        if background is None:
            with np.errstate(invalid="ignore", divide="ignore"):
                rgb = np.where(a > 0, rgb / np.maximum(a, 1e-12), 0.0)
            out = np.concatenate([rgb, a], axis=-1)
        else:
            bg = np.asarray(background, dtype=float).reshape(1, 1, 3)
            if np.any(bg < 0) or np.any(bg > 1):
                raise ValueError(f"background must be linear RGB in [0, 1], got {background}")
            out = rgb + (1.0 - a) * bg
        out = np.clip(out, 0.0, 1.0)
        if encoding == "srgb":
            out[..., :3] = _srgb_encode(out[..., :3])
        return np.rint(out * 255.0).astype(np.uint8)

    def _repr_png_(self) -> bytes:
        """Notebook display: :meth:`to_uint8` over black as PNG (:mod:`._repr`)."""
        return picture("image_png", self)

    def save(self, path, *, background: tuple[float, float, float] | None = (0.0, 0.0, 0.0),
             encoding: Literal["linear", "srgb"] = "linear") -> None:
        """Write a PNG (Pillow) of :meth:`to_uint8` ``(background, encoding)``; RGBA when ``background`` is None."""
        from PIL import Image as PILImage

        PILImage.fromarray(self.to_uint8(background, encoding)).save(path)
