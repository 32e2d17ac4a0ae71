"""Lights and shading models: the settings that decide how samples are lit (docs/design.md section 3).

Plain data that round-trips through JSON (:class:`~volumen.core._jsondata.JsonData`);
the renderers read them, nothing here computes light.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Literal, get_args

import numpy as np

from ._jsondata import JsonData, _choice, _nonneg, _vec

__all__ = ["FACING", "Light", "LightKind", "LIGHT_KINDS", "Shading", "ShadingMode", "SHADINGS", "PhongSettings",
           "ShadowSettings", "ScatterSettings", "PathTraceSettings"]

ShadingMode = Literal["none", "headlight", "phong", "shadows", "scattering", "pathtrace"]
LightKind = Literal["point", "spot", "headlight"]
SHADINGS: tuple[str, ...] = get_args(ShadingMode)
LIGHT_KINDS: tuple[str, ...] = get_args(LightKind)
#: two-sided lighting turns a sample's unit normal toward the viewer where ``N.V < -FACING``: a normal at right
#: angles to the view up to rounding (the edges of a slab seen face-on, of anything constant along the view: the
#: normal codes keep such a gradient in its plane exactly) keeps its side, where the sign of a rounding error
#: turned it one way or the other sample by sample (a speckle of lit and unlit edges); the renderers all read it
#: (``render.optics``, the shaders)
FACING = 1e-6


@dataclass(frozen=True, kw_only=True)
class Light(JsonData):
    """A point, spot or head light, fixed in world space or attached to the camera.

    Parameters
    ----------
    position : (3,) float, mm
        World RAS+ mm; with ``attach="camera"`` the offset from the eye along the
        camera's (right, up, forward) axes (``Camera.basis``), in mm.
    direction : (3,) float
        Spot axis (any length but zero; renderers normalize it), world RAS+ or,
        attached to the camera, along (right, up, forward).
    intensity : float
        Scales ``color``; >= 0. Lights do not fall off with distance: a sample
        facing the light receives ``intensity * color`` (times the spot factor).
    color : (3,) float
        Linear RGB.
    exponent : float
        Spot falloff of ``kind="spot"`` (and of a head light): the light reaching
        a sample is ``intensity * color * max(dot(L, D), 0) ** exponent``, with
        ``L`` the unit vector from the light to the sample and ``D`` the
        direction; ``exponent = 0`` shines every way.
    kind : {"point", "spot", "headlight"} or None
        ``point``: shines every way (``exponent`` ignored); ``spot``: the cone
        above; ``headlight``: at the eye, pointing along the view (``position``,
        ``direction`` and ``attach`` ignored; ``exponent`` applies). None (the
        default, and what older scene files hold) means ``spot`` when
        ``exponent > 0``, else ``point``.
    attach : {"world", "camera"}
        ``camera``: the light moves with the camera (an endoscope's flashlight).
    radius : float, mm
        Size of an area-like (spherical) light: the path tracer samples points
        in a ball of this radius, giving soft shadows; the ray-casting models
        use its centre. 0 = a point.
    """

    position: tuple[float, float, float] = (0.0, 0.0, 0.0)
    direction: tuple[float, float, float] = (0.0, 0.0, -1.0)
    intensity: float = 1.0
    color: tuple[float, float, float] = (1.0, 1.0, 1.0)
    exponent: float = 0.0
    kind: LightKind | None = None
    attach: Literal["world", "camera"] = "world"
    radius: float = 0.0

    def __post_init__(self) -> None:
        s = object.__setattr__
        s(self, "position", _vec("Light.position", self.position))
        s(self, "direction", _vec("Light.direction", self.direction, unit=True))
        s(self, "color", _vec("Light.color", self.color))
        s(self, "intensity", _nonneg("Light.intensity", self.intensity))
        s(self, "exponent", _nonneg("Light.exponent", self.exponent))
        s(self, "radius", _nonneg("Light.radius", self.radius))
        if self.kind is None:
            s(self, "kind", "spot" if self.exponent > 0 else "point")
        _choice("Light.kind", self.kind, LIGHT_KINDS)
        _choice("Light.attach", self.attach, ("world", "camera"))

    def in_world(self, camera) -> tuple[np.ndarray, np.ndarray]:
        """``(position mm, unit direction)`` in world RAS+ for ``camera`` (resolving head and attached lights)."""
        r, u, f = camera.basis()
        eye = np.asarray(camera.position, float)
        d = np.asarray(self.direction, float) / np.linalg.norm(self.direction)
        if self.kind == "headlight":
            return eye, f
        if self.attach == "camera":
            m = np.stack([r, u, f], axis=1)  # columns: camera axes in world
            return eye + m @ np.asarray(self.position, float), m @ d
        return np.asarray(self.position, float), d


def _set(obj, **values) -> None:
    for k, v in values.items():
        object.__setattr__(obj, k, v)


def _count(name: str, v, lo: int) -> int:
    if not (isinstance(v, (int, np.integer)) and not isinstance(v, bool) and v >= lo):
        raise ValueError(f"{name} must be an integer >= {lo}, got {v!r}")
    return int(v)


def _within(name: str, v, lo: float, hi: float, unit: str = "") -> float:
    if not lo <= float(v) <= hi:
        raise ValueError(f"{name} must be in [{lo}, {hi}]{unit}, got {v}")
    return float(v)


@dataclass(frozen=True, kw_only=True)
class PhongSettings(JsonData):
    """Phong terms (``headlight``, ``phong``, ``shadows``; in ``scattering`` / ``pathtrace``, ``ambient`` is the
    radiance of the uniform white environment and ``diffuse`` scales the lights).

    Parameters
    ----------
    ambient, diffuse, specular : float >= 0
    shininess : float >= 0
        Specular exponent.
    gradient : {"central", "sobel"}
        How normals are estimated from the data (scaled by the voxel spacing
        and the affine, so they are world-space directions).
    """

    ambient: float = 0.15
    diffuse: float = 0.65
    specular: float = 0.2
    shininess: float = 20.0
    gradient: Literal["central", "sobel"] = "central"

    def __post_init__(self) -> None:
        for name in ("ambient", "diffuse", "specular", "shininess"):
            _set(self, **{name: _nonneg(f"Shading.phong.{name}", getattr(self, name))})
        _choice("Shading.phong.gradient", self.gradient, ("central", "sobel"))


@dataclass(frozen=True, kw_only=True)
class ShadowSettings(JsonData):
    """How the light reaching a sample is found (``shadows``, ``scattering``).

    Parameters
    ----------
    method : {"fast", "direct"}
        ``direct``: a shadow ray marched per sample per light (the reference);
        ``fast``: a per-light illumination volume, built once per light /
        transfer function / clip box, read with one interpolation per sample.
    offset : float, reference steps (voxels)
        Where the path to the light starts, away from the sample (no self-shadowing).
    step : float in [0.05, 16], reference steps
        Step of the direct shadow rays.
    light_volume_scale : float in [0.05, 4]
        Resolution of the illumination volumes: light rays per voxel along each
        axis of the slices they are stored on (2: half-voxel spacing). Lowered
        automatically so one light's volume holds at most 1/8 value a voxel of
        the volume (a quarter of an int16 volume's bytes), or 2**22 values
        (16 MiB) where that is more.
    """

    method: Literal["fast", "direct"] = "fast"
    offset: float = 2.0
    step: float = 1.0
    light_volume_scale: float = 2.0

    def __post_init__(self) -> None:
        _choice("Shading.shadows.method", self.method, ("fast", "direct"))
        _set(self, offset=_nonneg("Shading.shadows.offset", self.offset),
             step=_within("Shading.shadows.step", self.step, 0.05, 16, " voxels"),
             light_volume_scale=_within("Shading.shadows.light_volume_scale", self.light_volume_scale, 0.05, 4.0))


@dataclass(frozen=True, kw_only=True)
class ScatterSettings(JsonData):
    """The participating medium of ``scattering`` and ``pathtrace``.

    Parameters
    ----------
    sigma_a, sigma_s : float >= 0, sum > 0
        Absorption and scattering coefficients in units of the transfer
        function's extinction ``-ln(1 - alpha) / ds0``: the medium has
        ``sigma_t = (sigma_a + sigma_s) * extinction`` and single-scattering
        albedo ``sigma_s / (sigma_a + sigma_s)`` (times the transfer function's colour).
    phase_g : float in [-0.95, 0.95]
        Henyey-Greenstein anisotropy (0 isotropic, > 0 forward scattering).
    """

    sigma_a: float = 0.0
    sigma_s: float = 1.0
    phase_g: float = 0.0

    def __post_init__(self) -> None:
        _set(self, sigma_a=_nonneg("Shading.scattering.sigma_a", self.sigma_a),
             sigma_s=_nonneg("Shading.scattering.sigma_s", self.sigma_s),
             phase_g=_within("Shading.scattering.phase_g", self.phase_g, -0.95, 0.95))
        if self.sigma_a + self.sigma_s <= 0:
            raise ValueError("Shading.scattering.sigma_a + sigma_s must be > 0")


@dataclass(frozen=True, kw_only=True)
class PathTraceSettings(JsonData):
    """Progressive path tracing (``pathtrace``).

    Parameters
    ----------
    samples : int >= 1
        Samples per pixel of one ``render`` call (32: denoised, as clean as 256 raw ones).
    bounces : int >= 1
        Most scattering events per path (1 = single scattering, which converges
        to the ``scattering`` picture).
    denoise : bool
        Denoise the pictures with Intel Open Image Denoise, fed the first
        scattering events' albedo and normal.
    """

    samples: int = 32
    bounces: int = 4
    denoise: bool = True

    def __post_init__(self) -> None:
        _set(self, samples=_count("Shading.pathtrace.samples", self.samples, 1),
             bounces=_count("Shading.pathtrace.bounces", self.bounces, 1), denoise=bool(self.denoise))


#: the settings of each model: Shading field -> its class
GROUPS = {"phong": PhongSettings, "shadows": ShadowSettings, "scattering": ScatterSettings,
          "pathtrace": PathTraceSettings}
#: the flat names of the settings before they were grouped (older scene files, keyword arguments)
#: -> (group, field)
FLAT = {"ambient": ("phong", "ambient"), "diffuse": ("phong", "diffuse"), "specular": ("phong", "specular"),
        "shininess": ("phong", "shininess"), "gradient": ("phong", "gradient"),
        "shadow_method": ("shadows", "method"), "shadow_offset": ("shadows", "offset"),
        "shadow_step": ("shadows", "step"), "light_volume_scale": ("shadows", "light_volume_scale"),
        "sigma_a": ("scattering", "sigma_a"), "sigma_s": ("scattering", "sigma_s"),
        "phase_g": ("scattering", "phase_g"), "pt_samples": ("pathtrace", "samples"),
        "pt_bounces": ("pathtrace", "bounces"), "pt_denoise": ("pathtrace", "denoise")}


@dataclass(frozen=True, kw_only=True)
class Shading(JsonData):
    """Lighting of samples (docs/design.md section 3): one ``mode``, all from the same kernels, and the settings of
    each model grouped.

    Parameters
    ----------
    mode : {"none", "headlight", "phong", "shadows", "scattering", "pathtrace"}
        ``none``: emission-absorption only. ``headlight``: Phong with one white
        point light at the eye. ``phong``: Phong with the scene's ``lights``.
        ``shadows``: ``phong`` with each light attenuated by
        ``1 - opacity accumulated`` from the sample toward the light.
        ``scattering``: physically based single scattering (Beer-Lambert to the
        eye and to each light, Henyey-Greenstein phase). ``pathtrace``:
        progressive Monte Carlo path tracing of the same medium (multiple
        scattering, soft shadows of area-like lights, the environment).
        In ``isosurface`` mode a surface has no medium: ``scattering`` and
        ``pathtrace`` light it as ``shadows`` does.
    phong : PhongSettings
    shadows : ShadowSettings
    scattering : ScatterSettings
    pathtrace : PathTraceSettings
        Each may be given as a dict of its fields.

    The flat names of :data:`FLAT` (``ambient``, ``shadow_method``,
    ``pt_samples``, ...) are accepted as keyword arguments and in older scene
    files (``from_dict``), and read as attributes, each standing for its
    field of a group (``Shading(ambient=0.3)`` is
    ``Shading(phong=PhongSettings(ambient=0.3))``).
    """

    mode: ShadingMode = "headlight"
    phong: PhongSettings = field(default_factory=PhongSettings)
    shadows: ShadowSettings = field(default_factory=ShadowSettings)
    scattering: ScatterSettings = field(default_factory=ScatterSettings)
    pathtrace: PathTraceSettings = field(default_factory=PathTraceSettings)

    def __init__(self, *, mode: ShadingMode = "headlight", phong=None, shadows=None, scattering=None, pathtrace=None,
                 **flat):
        unknown = set(flat) - set(FLAT)
        if unknown:
            raise ValueError(f"unknown Shading fields {sorted(unknown)}; valid: "
                             f"{sorted(['mode', *GROUPS, *FLAT])}")
        given = {"phong": phong, "shadows": shadows, "scattering": scattering, "pathtrace": pathtrace}
        for name, cls in GROUPS.items():
            g = given[name]
            g = cls() if g is None else (cls.from_dict(g) if isinstance(g, dict) else g)
            if not isinstance(g, cls):
                raise ValueError(f"Shading.{name} must be a {cls.__name__}, got {type(g).__name__}")
            over = {FLAT[k][1]: v for k, v in flat.items() if FLAT[k][0] == name}
            if over:
                try:
                    g = replace(g, **over)
                except ValueError as exc:  # name the flat keyword the caller used
                    used = ", ".join(k for k in flat if FLAT[k][0] == name)
                    raise ValueError(f"{exc} (given as {used})") from None
            _set(self, **{name: g})
        _set(self, mode=mode)
        _choice("Shading.mode", self.mode, SHADINGS)

    def __getattr__(self, name):
        if name in FLAT:
            group, key = FLAT[name]
            return getattr(getattr(self, group), key)
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    @classmethod
    def from_dict(cls, d: dict):
        """Inverse of :meth:`to_dict`; older flat files (``ambient``, ``pt_samples``, ...) load too."""
        return cls(**d)
