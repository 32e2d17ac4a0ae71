"""The result of a renderer: premultiplied linear RGBA, depth and statistics (docs/design.md section 2)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from ._repr import picture
from ._tonemap import Display, srgb_encode

__all__ = ["Image"]

_LINEAR = Display(tonemap="linear")


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
    display : Display or None
        How the picture is shown (:class:`~volumen.core.Display`, resolved: ``linear`` or ``aces``): the
        renderers set the scene's; None shows it linear.
    """

    rgba: np.ndarray
    depth: np.ndarray
    stats: dict[str, Any] = field(default_factory=dict)
    value: np.ndarray | None = None
    display: Display | None = None

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
                 encoding: Literal["linear", "srgb"] | None = None, gain: float = 1.0,
                 display: Display | None = None) -> np.ndarray:
        """8-bit picture for display or files, through the display transform (:class:`~volumen.core.Display`).

        Parameters
        ----------
        background : (3,) float in [0, 1], linear RGB, or None
            Composed under the image (``rgb + (1 - alpha) * background``),
            giving an ``(H, W, 3)`` uint8 array. None returns ``(H, W, 4)``
            with straight (un-premultiplied) alpha.
        encoding : {"linear", "srgb"} or None
            Of a ``linear`` display: ``linear`` (its default) writes the
            linear values as they are (``round(255 * v)``), as VTK and most
            volume renderers do, so transfer-function colours appear as
            authored; ``srgb`` applies the sRGB transfer curve. The filmic
            display always encodes sRGB (None, or ``srgb``).
        gain : float
            Display brightness: the colour (not the opacity) is scaled by
            ``gain`` (the application's brightness slider; with the filmic
            curve, before it).
        display : Display or None
            Overrides the image's own :attr:`display` (``auto`` resolves from
            ``stats["shading"]`` and ``stats["mode"]``).
        """
        disp = display if display is not None else (self.display or _LINEAR)
        if disp.tonemap == "auto":
            disp = disp.resolved(self.stats.get("shading", "none"), self.stats.get("mode", "composite"))
        if disp.tonemap != "linear":
            if encoding not in (None, "srgb"):
                raise ValueError(f"the {disp.tonemap!r} display encodes sRGB; got encoding={encoding!r}")
            _check_background(background)
            return np.rint(np.clip(disp.encode(self.rgba, background, gain), 0.0, 1.0) * 255.0).astype(np.uint8)
        encoding = "linear" if encoding is None else encoding
        if encoding not in ("linear", "srgb"):
            raise ValueError(f"encoding must be 'linear' or 'srgb', got {encoding!r}")
        if disp.exposure:
            gain = float(gain) * 2.0 ** disp.exposure
        rgb = self.rgba[..., :3].astype(np.float64) * float(gain)
        a = self.rgba[..., 3:4].astype(np.float64)
        if background is None:
            with np.errstate(invalid="ignore", divide="ignore"):
                rgb = np.where(a > 0, rgb / np.maximum(a, 1e-12), 0.0)
            out = np.concatenate([rgb, a], axis=-1)
        else:
            _check_background(background)
            out = rgb + (1.0 - a) * np.asarray(background, dtype=float).reshape(1, 1, 3)
        out = np.clip(out, 0.0, 1.0)
        if encoding == "srgb":
            out[..., :3] = srgb_encode(out[..., :3])
        return np.rint(out * 255.0).astype(np.uint8)

    def _repr_png_(self) -> bytes:
        """Notebook display: :meth:`to_uint8` over black as PNG (:mod:`._repr`)."""
        return picture("image_png", self)

    def save(self, path, *, background: tuple[float, float, float] | None = (0.0, 0.0, 0.0),
             encoding: Literal["linear", "srgb"] | None = None, display: Display | None = None) -> None:
        """Write a PNG (Pillow) of :meth:`to_uint8` ``(background, encoding, display=display)``; RGBA when
        ``background`` is None."""
        from PIL import Image as PILImage

        PILImage.fromarray(self.to_uint8(background, encoding, display=display)).save(path)


def _check_background(background) -> None:
    if background is None:
        return
    bg = np.asarray(background, dtype=float)
    if bg.shape != (3,) or np.any(bg < 0) or np.any(bg > 1):
        raise ValueError(f"background must be linear RGB in [0, 1], got {background}")
