"""Transfer functions: data value -> colour and opacity, piecewise linear.

Values are in the data's own units (HU for CT, docs/design.md section 2). Opacity
is given per reference step ``ds0`` = one voxel (the volume's smallest
spacing): a renderer stepping ``ds`` corrects it as
``a' = 1 - (1 - a) ** (ds / ds0)`` (render/optics.py). Outside its first and
last point a curve keeps its end value.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Literal, get_args

import numpy as np

from ..errors import UnknownChoiceError
from ._ct import hu_offset
from ._display import MR_CLEAR, display_range
from ._jsondata import JsonData
from ._projection import HEADROOM, SHOULDER, projection_window
from ._subject import subject_floor

__all__ = ["TransferFunction", "PRESETS", "Preset", "hu_offset", "default_preset", "fitted_preset", "is_color_slab"]

Preset = Literal["ct-bone", "ct-skin-bone", "ct-soft-tissue", "ct-vessels", "ct-lung", "ct-cinematic-bone",
                 "ct-cinematic-vessels", "ct-cinematic-soft-tissue", "mr-default", "mip-gray"]
PRESETS: tuple[str, ...] = get_args(Preset)


def _points(name: str, pts, width: int) -> tuple[tuple[float, ...], ...]:
    a = np.asarray(pts, dtype=float)
    if a.ndim != 2 or a.shape[1] != width or len(a) < 1:
        raise ValueError(f"{name} must be a list of ({'value, ' + ', '.join(['...'] * (width - 1))}) rows "
                         f"with {width} numbers each, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} holds non-finite numbers")
    if np.any(np.diff(a[:, 0]) < 0):
        raise ValueError(f"{name} values (first column) must be non-decreasing: {a[:, 0].tolist()}")
    if np.any(a[:, 1:] < 0) or np.any(a[:, 1:] > 1):
        raise ValueError(f"{name} colour/opacity entries must lie in [0, 1]")
    return tuple(tuple(float(x) for x in row) for row in a)


def _interp(x: np.ndarray, pts: tuple[tuple[float, ...], ...], col: int) -> np.ndarray:
    a = np.asarray(pts, dtype=float)
    return np.interp(x, a[:, 0], a[:, col])


@dataclass(frozen=True, kw_only=True)
class TransferFunction(JsonData):
    """Piecewise-linear colour and opacity over data values.

    Parameters
    ----------
    color : sequence of (value, r, g, b)
        Control points, values non-decreasing in the data's units, colours
        linear RGB in [0, 1].
    opacity : sequence of (value, alpha)
        Control points; alpha in [0, 1] per reference step (one voxel).
    gradient_opacity : sequence of (gradient magnitude, factor) or None
        Optional modulation: the opacity is multiplied by this piecewise-linear
        function of the gradient magnitude, in data units per mm (e.g. HU/mm).
    name : str
        Label (the preset's name for presets).
    """

    color: tuple[tuple[float, float, float, float], ...] = ((0.0, 0.0, 0.0, 0.0), (1.0, 1.0, 1.0, 1.0))
    opacity: tuple[tuple[float, float], ...] = ((0.0, 0.0), (1.0, 1.0))
    gradient_opacity: tuple[tuple[float, float], ...] | None = None
    name: str = ""

    def __post_init__(self) -> None:
        object.__setattr__(self, "color", _points("color", self.color, 4))
        object.__setattr__(self, "opacity", _points("opacity", self.opacity, 2))
        if self.gradient_opacity is not None:
            g = _points("gradient_opacity", self.gradient_opacity, 2)
            if g[0][0] < 0:
                raise ValueError("gradient_opacity magnitudes must be >= 0")
            object.__setattr__(self, "gradient_opacity", g)

    # -- evaluation ---------------------------------------------------------
    def evaluate(self, values) -> np.ndarray:
        """Colour and opacity at data ``values`` (any shape): float32 ``(..., 4)`` = r, g, b, alpha (straight,
        not premultiplied)."""
        v = np.asarray(values, dtype=float)
        out = np.empty(v.shape + (4,), np.float32)
        for c in range(3):
            out[..., c] = _interp(v, self.color, c + 1)
        out[..., 3] = _interp(v, self.opacity, 1)
        return out

    def gradient_factor(self, magnitude) -> np.ndarray:
        """Opacity factor at gradient ``magnitude`` (data units / mm); 1 where no modulation is set."""
        m = np.asarray(magnitude, dtype=float)
        if self.gradient_opacity is None:
            return np.ones(m.shape, np.float32)
        return _interp(m, self.gradient_opacity, 1).astype(np.float32)

    def lut(self, vmin: float, vmax: float, n: int = 4096) -> np.ndarray:
        """Bake into a table: float32 ``(n, 4)`` (r, g, b, alpha) at ``n`` values evenly spaced over [vmin, vmax]."""
        if not (np.isfinite(vmin) and np.isfinite(vmax)) or n < 2:
            raise ValueError(f"lut needs a finite range and n >= 2, got [{vmin}, {vmax}], n={n}")
        return self.evaluate(np.linspace(vmin, vmax, n))

    def visible_range(self) -> tuple[float, float]:
        """``(lo, hi)`` data values between which the opacity can be non-zero (inf where it stays non-zero)."""
        a = np.asarray(self.opacity)
        nz = np.nonzero(a[:, 1] > 0)[0]
        if len(nz) == 0:
            return (np.inf, -np.inf)
        lo = -np.inf if nz[0] == 0 else a[nz[0] - 1, 0]
        hi = np.inf if nz[-1] == len(a) - 1 else a[nz[-1] + 1, 0]
        return float(lo), float(hi)

    # -- editing ------------------------------------------------------------
    def shifted(self, offset: float) -> TransferFunction:
        """Slicer-style shift: move the inner control points by ``offset`` data units.

        The first and last point of each curve stay (they anchor the ends of
        the range); the inner ones are clamped between them so the curve stays
        ordered.
        """

        def move(pts):
            if len(pts) <= 2:
                return pts
            lo, hi = pts[0][0], pts[-1][0]
            inner = tuple((min(max(p[0] + offset, lo), hi),) + tuple(p[1:]) for p in pts[1:-1])
            return (pts[0],) + inner + (pts[-1],)

        return replace(self, color=move(self.color), opacity=move(self.opacity))

    def with_opacity_scale(self, factor: float) -> TransferFunction:
        """A copy with every opacity multiplied by ``factor`` (clipped to [0, 1])."""
        return replace(self, opacity=tuple((v, min(max(a * factor, 0.0), 1.0)) for v, a in self.opacity))

    # -- constructors -------------------------------------------------------
    @classmethod
    def window_level(cls, window: float, level: float, *, opacity: tuple[float, float] = (0.0, 1.0),
                     name: str = "") -> TransferFunction:
        """Grayscale ramp: black at ``level - window/2``, white at ``level + window/2`` (data units).

        ``opacity`` gives the alpha at the bottom and top of the window (ramped
        linearly between them, constant outside).
        """
        if not window > 0:
            raise ValueError(f"window must be > 0, got {window}")
        lo, hi = level - window / 2, level + window / 2
        return cls(color=((lo, 0.0, 0.0, 0.0), (hi, 1.0, 1.0, 1.0)),
                   opacity=((lo, opacity[0]), (hi, opacity[1])), name=name)

    @classmethod
    def preset(cls, name: Preset, *, value_range: tuple[float, float] | None = None) -> TransferFunction:
        """A named preset.

        CT presets are in Hounsfield units. ``mr-default`` and ``mip-gray`` are
        relative to the data's ``value_range = (min, max)``, which they need.
        Valid names: see ``PRESETS``.
        """
        if name not in PRESETS:
            raise UnknownChoiceError("transfer function preset", name, PRESETS)
        if name in _CT_PRESETS:
            color, opacity = _CT_PRESETS[name]
            return cls(color=color, opacity=opacity, name=name)
        if value_range is None:
            raise ValueError(f"preset {name!r} is relative to the data: pass value_range=(min, max)")
        lo, hi = (float(x) for x in value_range)
        if not hi > lo:
            hi = lo + 1.0
        span = hi - lo
        if name == "mip-gray":
            return cls.window_level(span, lo + span / 2, opacity=(1.0, 1.0), name=name)
        # mr-default: the background (the bottom MR_CLEAR of the range) transparent, a warm ramp above
        return cls(color=((lo, 0.0, 0.0, 0.0), (lo + 0.15 * span, 0.55, 0.35, 0.3),
                          (lo + 0.5 * span, 0.95, 0.85, 0.75), (hi, 1.0, 1.0, 1.0)),
                   opacity=((lo, 0.0), (lo + MR_CLEAR * span, 0.0), (lo + 0.3 * span, 0.05),
                            (lo + 0.7 * span, 0.3), (hi, 0.5)), name=name)



# Hounsfield-unit presets: (colour points, opacity points); opacity per voxel step.
_CT_PRESETS = {
    # after 3D Slicer's CT-Bone, with the opacity ramp starting at 120 HU instead of -16 HU so soft
    # tissue (< 100 HU) stays transparent through a whole trunk and only bone (and contrast) shows
    "ct-bone": (((-3024, 0, 0, 0), (-16, 0.73, 0.25, 0.30), (641, 0.91, 0.82, 0.55), (3071, 1, 1, 1)),
                ((-3024, 0), (120, 0), (641, 0.72), (3071, 0.71))),
    # a thin translucent skin layer at the air/tissue boundary, opaque bone
    "ct-skin-bone": (((-3024, 0, 0, 0), (-600, 0.85, 0.6, 0.5), (0, 0.9, 0.65, 0.55), (250, 0.9, 0.85, 0.75),
                      (3071, 1, 1, 1)),
                     ((-3024, 0), (-650, 0), (-500, 0.6), (-300, 0.6), (-150, 0.02), (150, 0.0), (250, 0.3),
                      (700, 0.85), (3071, 0.9))),
    # soft-tissue window (W 400, L 40) with a ramp in opacity
    "ct-soft-tissue": (((-3024, 0, 0, 0), (-160, 0.55, 0.25, 0.15), (40, 0.85, 0.45, 0.35), (240, 1, 0.9, 0.8),
                        (3071, 1, 1, 1)),
                       ((-3024, 0), (-160, 0), (40, 0.08), (240, 0.3), (3071, 0.5))),
    # contrast-filled vessels (~150-400 HU) red, bone pale
    "ct-vessels": (((-3024, 0, 0, 0), (120, 0.6, 0.05, 0.05), (300, 0.9, 0.2, 0.15), (600, 1, 0.9, 0.8),
                    (3071, 1, 1, 1)),
                   ((-3024, 0), (110, 0), (200, 0.5), (600, 0.75), (3071, 0.8))),
    # cinematic presets: colours and opacities chosen with the studio rig's light (key, fill, rim over a sky) and
    # the filmic display, for the path tracer and the shadowed models; the medium's albedo is the colour, so the
    # colours are those of the tissue lit white (ivory bone, red contrast blood), not pre-shaded
    # bone alone: a firm surface from 150 HU, cortical bone ivory, marrow warmer
    "ct-cinematic-bone": (((-3024, 0, 0, 0), (150, 0.75, 0.5, 0.4), (350, 0.9, 0.82, 0.7), (900, 0.97, 0.94, 0.88),
                           (3071, 1, 1, 1)),
                          ((-3024, 0), (150, 0), (300, 0.7), (600, 0.95), (3071, 0.98))),
    # contrast-filled vessels (150-450 HU) deep red, bone ivory behind them
    "ct-cinematic-vessels": (((-3024, 0, 0, 0), (130, 0.55, 0.06, 0.04), (280, 0.85, 0.16, 0.1),
                              (480, 0.95, 0.85, 0.75), (1000, 0.98, 0.95, 0.9), (3071, 1, 1, 1)),
                             ((-3024, 0), (120, 0), (220, 0.75), (500, 0.9), (3071, 0.95))),
    # soft tissue: fat faint and yellow, muscle and organs red-brown and firmer, bone opaque
    "ct-cinematic-soft-tissue": (((-3024, 0, 0, 0), (-150, 0.85, 0.7, 0.45), (20, 0.72, 0.3, 0.24),
                                  (120, 0.85, 0.5, 0.42), (300, 0.95, 0.9, 0.82), (3071, 1, 1, 1)),
                                 ((-3024, 0), (-400, 0), (-120, 0.02), (-60, 0.02), (20, 0.12), (100, 0.3),
                                  (300, 0.8), (3071, 0.9))),
    # lung parenchyma and airway walls; everything denser than -200 HU transparent
    "ct-lung": (((-3024, 0, 0, 0), (-950, 0.9, 0.6, 0.55), (-600, 1, 0.8, 0.75), (-200, 1, 0.95, 0.9),
                 (3071, 1, 1, 1)),
                ((-3024, 0), (-950, 0), (-850, 0.02), (-600, 0.1), (-300, 0.06), (-200, 0), (3071, 0))),
}


def is_color_slab(volume) -> bool:
    """Whether ``volume`` is a colour slab (``Volume.thin_axis``): a colour frame or a cine of a few (ultrasound,
    a photograph, a secondary capture), which is drawn as the image it is (:func:`default_preset`, and no shading:
    ``render.default_shading``)."""
    return bool(volume.is_color) and volume.thin_axis is not None


def default_preset(volume, mode: str | None = "composite") -> TransferFunction:
    """The transfer function for a volume drawn with none named: a gray ramp over the data range for the
    projections, and opaque for a colour slab (:func:`is_color_slab`: its own colours, the frame facing the
    viewer); for CT (:func:`is_ct`) ``ct-skin-bone`` (skin over bone: anatomy, not a box), moved onto the
    stored values (:func:`hu_offset`); ``mr-default`` otherwise (over its display range: :func:`fitted_preset`).
    Its ``name`` says which."""
    if mode in ("mip", "minip", "average") or (mode in (None, "composite") and is_color_slab(volume)):
        return fitted_preset("mip-gray", volume)
    return fitted_preset("ct-skin-bone" if hu_offset(volume) is not None else "mr-default", volume)


def _projection_gray(black: float, knee: float, white: float) -> TransferFunction:
    """``mip-gray`` over a projection's window (:func:`projection_window`): black, the knee's grey, white; opaque."""
    g = 1.0 - SHOULDER
    return TransferFunction(color=((black, 0.0, 0.0, 0.0), (knee, g, g, g), (white, 1.0, 1.0, 1.0)),
                            opacity=((black, 1.0), (white, 1.0)), name="mip-gray")


def fitted_preset(name: str, volume) -> TransferFunction:
    """Preset ``name`` for ``volume``: a Hounsfield-unit preset moved onto a CT's stored values (:func:`hu_offset`);
    ``mr-default`` over the volume's display range (:func:`display_range`: its data range, less far outliers);
    ``mip-gray`` over the values the volume's projections show (:func:`projection_window`: a projection shows
    the brightest voxel along each ray, so never the background inside the subject; spanned over the voxels'
    values an MRI's MIP took the top of the ramp, milky, its brightest tissue white), black to a shade below white
    at the knee and on to white at the projections' maximum; where that window cannot be read (a chunked volume, a
    label map) over the display range, from the subject's darkest tissue (:func:`subject_floor`) in a scan that
    is not a CT, with the same shoulder above its top. Every place that names a preset for a volume asks here,
    so a preset picked again is the default it was."""
    if name in _CT_PRESETS:
        tf, offset = TransferFunction.preset(name), hu_offset(volume)
        return tf.shifted(offset) if offset else tf
    bottom, top = display_range(volume)
    if name != "mip-gray" or volume.is_color:
        return TransferFunction.preset(name, value_range=(bottom, top))
    window = projection_window(volume)
    if window is None:  # the display range, from the subject's darkest tissue in a scan that is not a CT
        floor = subject_floor(volume) if hu_offset(volume) is None else None
        bottom = bottom if floor is None or not floor < top else max(bottom, floor)
        window = (bottom, top, top + HEADROOM * (top - bottom)) if top > bottom else None
    return _projection_gray(*window) if window else TransferFunction.preset(name, value_range=(bottom, top))

