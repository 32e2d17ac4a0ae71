"""Lights and shading models: the settings that decide how samples are lit (DESIGN.md section 3).

Plain data that round-trips through JSON (:class:`~volumen.core._jsondata.JsonData`);
the renderers read them, nothing here computes light.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal, get_args

import numpy as np

from ._jsondata import JsonData, _choice, _nonneg, _vec

__all__ = ["Light", "LightKind", "LIGHT_KINDS", "Shading", "ShadingMode", "SHADINGS"]

ShadingMode = Literal["none", "headlight", "phong", "shadows", "scattering", "pathtrace"]
LightKind = Literal["point", "spot", "headlight"]
SHADINGS: tuple[str, ...] = get_args(ShadingMode)
LIGHT_KINDS: tuple[str, ...] = get_args(LightKind)


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


@dataclass(frozen=True, kw_only=True)
class Shading(JsonData):
    """Lighting of samples (DESIGN.md section 3): one ``mode``, all from the same kernels.

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
    ambient, diffuse, specular : float
        Phong coefficients. In ``scattering`` and ``pathtrace``, ``ambient`` is
        the radiance of the uniform white environment (unshadowed in
        ``scattering``) and ``diffuse`` scales the lights.
    shininess : float
        Specular exponent.
    gradient : {"central", "sobel"}
        How normals are estimated from the data (scaled by the voxel spacing
        and the affine, so they are world-space directions).
    shadow_method : {"fast", "direct"}
        ``direct``: a shadow ray marched per sample per light (the reference);
        ``fast``: a per-light illumination volume, built once per light /
        transfer function / clip box, read with one interpolation per sample.
    shadow_offset : float, reference steps (voxels)
        Where the path to the light starts, away from the sample (no
        self-shadowing).
    shadow_step : float, reference steps (voxels)
        Step of the direct shadow rays.
    light_volume_scale : float in [0.05, 4]
        Resolution of the illumination volumes: light rays per voxel along each
        axis of the slices they are stored on (2: half-voxel spacing). Lowered
        automatically so one light's volume holds at most 2**26 values (256 MB).
    sigma_a, sigma_s : float
        Absorption and scattering coefficients in units of the transfer
        function's extinction ``-ln(1 - alpha) / ds0``: the medium has
        ``sigma_t = (sigma_a + sigma_s) * extinction`` and single-scattering
        albedo ``sigma_s / (sigma_a + sigma_s)`` (times the transfer function's
        colour). ``scattering`` and ``pathtrace`` only.
    phase_g : float in [-0.95, 0.95]
        Henyey-Greenstein anisotropy (0 isotropic, > 0 forward scattering).
    pt_samples : int
        Samples per pixel of one ``render`` call in ``pathtrace`` mode.
    pt_bounces : int
        Most scattering events per path (1 = single scattering, which converges
        to the ``scattering`` picture).
    """

    mode: ShadingMode = "headlight"
    ambient: float = 0.15
    diffuse: float = 0.65
    specular: float = 0.2
    shininess: float = 20.0
    gradient: Literal["central", "sobel"] = "central"
    shadow_method: Literal["fast", "direct"] = "fast"
    shadow_offset: float = 2.0
    shadow_step: float = 1.0
    light_volume_scale: float = 2.0
    sigma_a: float = 0.0
    sigma_s: float = 1.0
    phase_g: float = 0.0
    pt_samples: int = 64
    pt_bounces: int = 4

    def __post_init__(self) -> None:
        _choice("Shading.mode", self.mode, SHADINGS)
        _choice("Shading.gradient", self.gradient, ("central", "sobel"))
        _choice("Shading.shadow_method", self.shadow_method, ("fast", "direct"))
        for name in ("ambient", "diffuse", "specular", "shininess", "shadow_offset", "sigma_a", "sigma_s"):
            object.__setattr__(self, name, _nonneg(f"Shading.{name}", getattr(self, name)))
        if not 0.05 <= float(self.shadow_step) <= 16:
            raise ValueError(f"Shading.shadow_step must be in [0.05, 16] voxels, got {self.shadow_step}")
        if not 0.05 <= float(self.light_volume_scale) <= 4.0:
            raise ValueError(f"Shading.light_volume_scale must be in [0.05, 4], got {self.light_volume_scale}")
        if not -0.95 <= float(self.phase_g) <= 0.95:
            raise ValueError(f"Shading.phase_g must be in [-0.95, 0.95], got {self.phase_g}")
        if self.sigma_a + self.sigma_s <= 0:
            raise ValueError("Shading.sigma_a + Shading.sigma_s must be > 0")
        for name, lo in (("pt_samples", 1), ("pt_bounces", 1)):
            v = getattr(self, name)
            if not (isinstance(v, (int, np.integer)) and not isinstance(v, bool) and v >= lo):
                raise ValueError(f"Shading.{name} must be an integer >= {lo}, got {v!r}")
            object.__setattr__(self, name, int(v))
        for name in ("shadow_step", "light_volume_scale", "phase_g"):
            object.__setattr__(self, name, float(getattr(self, name)))
