"""The display transform: exposure, a filmic tone curve and sRGB encoding, from linear radiance to display values.

Renderers return linear, premultiplied radiance (docs/design.md section 5); this is the one place it becomes a
picture for a screen or a file (:meth:`volumen.core.Image.to_uint8`, which the PNG writer, the videos, the
application and the notebook all call). :class:`Display` is the setting, declared once with the scene
(``Scene.display``) and carried by the rendered :class:`~volumen.core.Image`, so every surface shows the same
picture.

* ``linear``: no curve, linear encoding, exposure 0: the pictures of volumen before the display transform,
  bit for bit (``round(255 * clip(rgb + (1 - alpha) * background))``).
* ``aces``: the ACES filmic curve as fitted by Narkowicz (2015),
  ``f(x) = x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14)`` on each channel, after the exposure, then the sRGB
  encoding of IEC 61966-2-1 (:func:`srgb_encode`).

Exposure (stops, ``2 ** EV`` times the radiance): given, or metered on the picture (``exposure=None``): the
median luminance of the subject (pixels of alpha > 0.5, else every covered pixel, weighted by alpha) is set to
the radiance the curve shows as middle grey (0.18 after the curve, 0.46 encoded), as a camera's averaging meter
does; clamped to [-4, +8] stops.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal, get_args

import numpy as np

from ._jsondata import JsonData, _choice

__all__ = ["Display", "Tonemap", "TONEMAPS", "aces", "aces_inverse", "srgb_encode", "meter", "luminance",
           "LIT_SHADINGS", "ACES", "SRGB", "shader_constants"]

Tonemap = Literal["auto", "linear", "aces"]
TONEMAPS: tuple[str, ...] = get_args(Tonemap)
#: shading modes whose pictures are light transport (they use the scene's lights): ``auto`` tone maps them
LIT_SHADINGS = ("phong", "shadows", "scattering", "pathtrace")
#: Rec. 709 / sRGB luminance weights of linear R, G, B
LUMA = (0.2126, 0.7152, 0.0722)
#: display value (linear, after the curve) of the metered subject's median: photographic middle grey
MIDDLE_GREY = 0.18
#: range of a metered exposure, stops
METER_RANGE = (-4.0, 8.0)
#: Narkowicz's ACES fit ``x (A x + B) / (x (C x + D) + E)``: (A, B, C, D, E)
ACES = (2.51, 0.03, 2.43, 0.59, 0.14)
#: sRGB transfer function: (linear-segment limit, its slope, scale, exponent, offset) of IEC 61966-2-1
SRGB = (0.0031308, 12.92, 1.055, 2.4, 0.055)
_A, _B, _C, _D, _E = ACES


def srgb_encode(x: np.ndarray) -> np.ndarray:
    """The sRGB transfer function (IEC 61966-2-1) of linear values in [0, 1]."""
    x = np.asarray(x, dtype=np.float64)
    lim, slope, k, gamma, off = SRGB
    return np.where(x <= lim, slope * x, k * np.power(np.maximum(x, lim), 1 / gamma) - off)


def aces(x: np.ndarray) -> np.ndarray:
    """Narkowicz's fit of the ACES filmic curve (RRT + ODT), clipped to [0, 1]; ``x`` linear radiance >= 0."""
    x = np.maximum(np.asarray(x, dtype=np.float64), 0.0)
    return np.clip(x * (_A * x + _B) / (x * (_C * x + _D) + _E), 0.0, 1.0)


def aces_inverse(y: float) -> float:
    """The radiance :func:`aces` maps to ``y`` in [0, 1) (the positive root of its quadratic)."""
    a, b, c = _A - _C * y, _B - _D * y, -_E * y
    return float((-b + math.sqrt(b * b - 4 * a * c)) / (2 * a)) if abs(a) > 1e-12 else float(-c / b)


def luminance(rgb: np.ndarray) -> np.ndarray:
    """Rec. 709 luminance of linear RGB ``(..., 3)``."""
    rgb = np.asarray(rgb, dtype=np.float64)
    return rgb[..., 0] * LUMA[0] + rgb[..., 1] * LUMA[1] + rgb[..., 2] * LUMA[2]


def meter(rgba: np.ndarray) -> float:
    """Exposure (stops) that shows the subject's median luminance as middle grey through :func:`aces`.

    ``rgba`` (H, W, 4) premultiplied linear. The subject is the pixels of alpha > 0.5 (every pixel of alpha > 0
    where none is that opaque); its luminance is the straight colour's. 0 when nothing is drawn.
    """
    a = np.asarray(rgba[..., 3], dtype=np.float64)
    sel = a > 0.5
    if not sel.any():
        sel = a > 0.0
        if not sel.any():
            return 0.0
    lum = luminance(rgba[..., :3][sel]) / a[sel]
    med = float(np.median(lum))
    if not med > 0.0:
        return METER_RANGE[1]
    ev = math.log2(aces_inverse(MIDDLE_GREY) / med)
    return float(min(max(ev, METER_RANGE[0]), METER_RANGE[1]))


def shader_constants() -> dict:
    """The constants of this module a shader or a page applying the same transform needs (JSON-ready): the
    curve's and the encoding's coefficients, the luminance weights, the radiance metered subjects are shown
    at (``aces_inverse(MIDDLE_GREY)``) and the metered exposure's range (the browser viewer: ``display.glsl``)."""
    return {"aces": list(ACES), "srgb": list(SRGB), "luma": list(LUMA), "grey": aces_inverse(MIDDLE_GREY),
            "range": list(METER_RANGE)}


@dataclass(frozen=True, kw_only=True)
class Display(JsonData):
    """How linear radiance becomes display values (see the module): tone curve, exposure, encoding.

    Parameters
    ----------
    tonemap : {"auto", "linear", "aces"}
        ``linear``: the values as they are, linear encoding (volumen's pictures before the display transform,
        bit for bit); ``aces``: the ACES filmic curve then sRGB encoding; ``auto`` (default): ``aces`` for the
        lit shading models (:data:`LIT_SHADINGS`: phong, shadows, scattering, pathtrace), ``linear`` for the
        others (unlit, headlight, the projections), whose colours are the transfer function's as authored.
    exposure : float or None, stops
        The radiance is multiplied by ``2 ** exposure`` first. None (default): metered on each picture
        (:func:`meter`) with ``aces``, 0 with ``linear``.
    """

    tonemap: Tonemap = "auto"
    exposure: float | None = None

    def __post_init__(self) -> None:
        _choice("Display.tonemap", self.tonemap, TONEMAPS)
        if self.exposure is not None:
            if not (isinstance(self.exposure, (int, float, np.floating)) and np.isfinite(self.exposure)
                    and abs(self.exposure) <= 32):
                raise ValueError(f"Display.exposure must be a number of stops in [-32, 32] or None, "
                                 f"got {self.exposure!r}")
            object.__setattr__(self, "exposure", float(self.exposure))

    def resolved(self, shading: str, mode: str = "composite") -> Display:
        """This display with ``auto`` replaced by the curve for a picture of ``shading`` in ``mode``."""
        if self.tonemap != "auto":
            return self
        lit = shading in LIT_SHADINGS and mode in ("composite", "isosurface")
        return Display(tonemap="aces" if lit else "linear", exposure=self.exposure)

    def stops(self, rgba: np.ndarray) -> float:
        """The exposure applied to ``rgba``: the given one, else metered (aces) or 0 (linear)."""
        if self.exposure is not None:
            return self.exposure
        return meter(rgba) if self.tonemap == "aces" else 0.0

    def encode(self, rgba: np.ndarray, background, gain: float = 1.0) -> np.ndarray:
        """Display values in [0, 1] of premultiplied ``rgba`` through the filmic curve (``tonemap == "aces"``):
        ``(H, W, 3)`` over ``background`` (display values in [0, 1]), or ``(H, W, 4)`` straight colour and alpha
        when ``background`` is None; the background (linear RGB in [0, 1]) is encoded, not tone mapped, and composed
        in display values, so it shows as given. ``gain`` multiplies the exposure (a viewer's brightness)."""
        if self.tonemap != "aces":
            raise ValueError(f"encode is the filmic path; tonemap {self.tonemap!r} goes through Image.to_uint8")
        k = float(gain) * 2.0 ** self.stops(rgba)
        a = np.asarray(rgba[..., 3:4], dtype=np.float64)
        with np.errstate(invalid="ignore", divide="ignore"):
            straight = np.where(a > 0, np.asarray(rgba[..., :3], np.float64) / np.maximum(a, 1e-12), 0.0)
        shown = srgb_encode(aces(k * straight))
        if background is None:
            return np.concatenate([shown, np.clip(a, 0.0, 1.0)], axis=-1)
        a = np.clip(a, 0.0, 1.0)
        return a * shown + (1.0 - a) * srgb_encode(np.asarray(background, float).reshape(1, 1, 3))
