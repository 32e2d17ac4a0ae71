"""What a picture shows: the Scene and its settings, all plain data that round-trips through JSON.

A :class:`Scene` holds the :class:`~volumen.core.Volume` object at run time,
but its JSON holds only ``volume_ref``, a string naming where the volume comes
from (a file path, or a phantom name such as ``"phantom:head"``). Resolving
that string is the caller's job (the command line and the application pass a
``resolve`` function to :meth:`Scene.from_dict`), so ``core`` never reads files.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field, replace
from typing import Any, Callable, Literal, get_args

import numpy as np

from ._jsondata import JsonData
from ._transfer import TransferFunction

__all__ = ["Light", "LightKind", "LIGHT_KINDS", "Shading", "Sampling", "ClipPlane", "Clipping", "Isosurface", "Scene",
           "Mode", "ShadingMode", "MODES", "SHADINGS"]

Mode = Literal["composite", "mip", "minip", "average", "isosurface"]
ShadingMode = Literal["none", "headlight", "phong", "shadows", "scattering", "pathtrace"]
LightKind = Literal["point", "spot", "headlight"]
MODES: tuple[str, ...] = get_args(Mode)
SHADINGS: tuple[str, ...] = get_args(ShadingMode)
LIGHT_KINDS: tuple[str, ...] = get_args(LightKind)


def _choice(name: str, value, choices) -> None:
    if value not in choices:
        raise ValueError(f"{name} must be one of {', '.join(map(repr, choices))}; got {value!r}")


def _vec(name: str, v, n: int = 3, unit: bool = False) -> tuple[float, ...]:
    a = np.asarray(v, dtype=float).ravel()
    if a.shape != (n,) or not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be {n} finite numbers, got {v!r}")
    if unit and np.linalg.norm(a) < 1e-12:  # kept as given (exact JSON round trip); renderers normalize
        raise ValueError(f"{name} must not be the zero vector")
    return tuple(float(x) for x in a)


def _nonneg(name: str, v) -> float:
    v = float(v)
    if not (np.isfinite(v) and v >= 0):
        raise ValueError(f"{name} must be a finite number >= 0, got {v}")
    return v


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


@dataclass(frozen=True, kw_only=True)
class Sampling(JsonData):
    """How rays sample the volume.

    Parameters
    ----------
    samples_per_voxel : float
        Step ``ds = ds0 / samples_per_voxel`` with ``ds0`` the smallest voxel spacing (mm).
    interpolation : {"linear", "nearest"}
        Trilinear or nearest-voxel reconstruction.
    jitter : bool
        Offset each ray's first sample by a fraction of a step from a
        deterministic hash of (pixel, ``seed``), against wood-grain artifacts.
    seed : int
        Frame seed of the jitter.
    early_termination : float
        Stop a composite ray once its opacity reaches this (1.0 disables).
    skip_empty : bool
        Skip blocks of the volume that cannot contribute (min/max block grid).
    block_size : int
        Edge in voxels of the empty-space blocks.
    preintegrate : bool
        Pre-integrated classification (composite mode).
    """

    samples_per_voxel: float = 1.0
    interpolation: Literal["linear", "nearest"] = "linear"
    jitter: bool = True
    seed: int = 0
    early_termination: float = 0.99
    skip_empty: bool = True
    block_size: int = 8
    preintegrate: bool = False

    def __post_init__(self) -> None:
        if not (np.isfinite(self.samples_per_voxel) and 0.01 <= self.samples_per_voxel <= 64):
            raise ValueError(f"samples_per_voxel must be in [0.01, 64], got {self.samples_per_voxel}")
        object.__setattr__(self, "samples_per_voxel", float(self.samples_per_voxel))
        _choice("Sampling.interpolation", self.interpolation, ("linear", "nearest"))
        if not 0.0 < self.early_termination <= 1.0:
            raise ValueError(f"early_termination must be in (0, 1], got {self.early_termination}")
        object.__setattr__(self, "early_termination", float(self.early_termination))
        if not (isinstance(self.block_size, (int, np.integer)) and 2 <= self.block_size <= 64):
            raise ValueError(f"block_size must be an integer in [2, 64], got {self.block_size!r}")
        object.__setattr__(self, "block_size", int(self.block_size))
        object.__setattr__(self, "seed", int(self.seed))
        object.__setattr__(self, "jitter", bool(self.jitter))
        object.__setattr__(self, "skip_empty", bool(self.skip_empty))
        object.__setattr__(self, "preintegrate", bool(self.preintegrate))


@dataclass(frozen=True, kw_only=True)
class ClipPlane(JsonData):
    """A clip plane in world RAS+ mm; the half-space the ``normal`` points into is KEPT:
    points ``x`` with ``dot(x - point, normal) >= 0`` are drawn. ``normal``: any length but zero."""

    point: tuple[float, float, float]
    normal: tuple[float, float, float]

    def __post_init__(self) -> None:
        object.__setattr__(self, "point", _vec("ClipPlane.point", self.point))
        object.__setattr__(self, "normal", _vec("ClipPlane.normal", self.normal, unit=True))


@dataclass(frozen=True, kw_only=True)
class Clipping(JsonData):
    """What part of the volume is drawn.

    Parameters
    ----------
    crop : (6,) float or None
        Box ``(xmin, xmax, ymin, ymax, zmin, zmax)``: in voxel indices
        ``(i, j, k)`` (column, row, slice; voxel centres at integers) when
        ``crop_space == "voxel"``, in world RAS+ mm (axis-aligned) when
        ``"world"``. The box is intersected with the volume's box.
    crop_space : {"voxel", "world"}
    planes : sequence of ClipPlane
        Up to 6; each keeps the half-space its normal points into.
    """

    crop: tuple[float, float, float, float, float, float] | None = None
    crop_space: Literal["voxel", "world"] = "voxel"
    planes: tuple[ClipPlane, ...] = ()

    def __post_init__(self) -> None:
        _choice("Clipping.crop_space", self.crop_space, ("voxel", "world"))
        if self.crop is not None:
            c = _vec("Clipping.crop", self.crop, 6)
            if c[1] < c[0] or c[3] < c[2] or c[5] < c[4]:
                raise ValueError(f"Clipping.crop must be (xmin, xmax, ymin, ymax, zmin, zmax) with min <= max, got {c}")
            object.__setattr__(self, "crop", c)
        planes = tuple(p if isinstance(p, ClipPlane) else ClipPlane.from_dict(p) for p in self.planes)
        if len(planes) > 6:
            raise ValueError(f"at most 6 clip planes, got {len(planes)}")
        object.__setattr__(self, "planes", planes)


@dataclass(frozen=True, kw_only=True)
class Isosurface(JsonData):
    """The isosurface mode's threshold (data units) and colour (linear RGB)."""

    value: float = 0.0
    color: tuple[float, float, float] = (0.9, 0.85, 0.75)

    def __post_init__(self) -> None:
        if not np.isfinite(self.value):
            raise ValueError("Isosurface.value must be finite")
        object.__setattr__(self, "value", float(self.value))
        object.__setattr__(self, "color", _vec("Isosurface.color", self.color))


@dataclass(frozen=True, kw_only=True)
class Scene:
    """Everything but the camera that decides a picture.

    Parameters
    ----------
    volume : Volume or None
        The data, at run time; not part of equality nor of the JSON.
    volume_ref : str
        Where the volume comes from (a path or ``"phantom:NAME"``); written to JSON.
    transfer : TransferFunction
    lights : sequence of Light
        Used by the shading modes ``phong``, ``shadows``, ``scattering`` and
        ``pathtrace`` (any number).
    mode : {"composite", "mip", "minip", "average", "isosurface"}
    shading, sampling, clipping, isosurface :
        The settings dataclasses.
    """

    volume: Any = field(default=None, compare=False, repr=False)
    volume_ref: str = ""
    transfer: TransferFunction = field(default_factory=TransferFunction)
    lights: tuple[Light, ...] = ()
    mode: Mode = "composite"
    shading: Shading = field(default_factory=Shading)
    sampling: Sampling = field(default_factory=Sampling)
    clipping: Clipping = field(default_factory=Clipping)
    isosurface: Isosurface = field(default_factory=Isosurface)

    def __post_init__(self) -> None:
        _choice("Scene.mode", self.mode, MODES)
        object.__setattr__(self, "lights", tuple(self.lights))
        for name, cls in (("transfer", TransferFunction), ("shading", Shading), ("sampling", Sampling),
                          ("clipping", Clipping), ("isosurface", Isosurface)):
            if not isinstance(getattr(self, name), cls):
                raise ValueError(f"Scene.{name} must be a {cls.__name__}, got {type(getattr(self, name)).__name__}")
        for light in self.lights:
            if not isinstance(light, Light):
                raise ValueError(f"Scene.lights must hold Light objects, got {type(light).__name__}")

    def with_(self, **changes) -> "Scene":
        """A copy with some fields changed (validated again)."""
        return replace(self, **changes)

    def to_dict(self) -> dict:
        """JSON-ready dict; the volume appears only as ``volume`` = ``volume_ref``."""
        return {"volume": self.volume_ref, "transfer": self.transfer.to_dict(),
                "lights": [lt.to_dict() for lt in self.lights], "mode": self.mode,
                "shading": self.shading.to_dict(), "sampling": self.sampling.to_dict(),
                "clipping": self.clipping.to_dict(), "isosurface": self.isosurface.to_dict()}

    @classmethod
    def from_dict(cls, d: dict, *, volume=None, resolve: Callable[[str], Any] | None = None) -> "Scene":
        """Inverse of :meth:`to_dict`.

        ``volume`` is attached as is; otherwise, when ``resolve`` is given, it
        is called with the stored reference string and must return the Volume.
        """
        known = {"volume", "transfer", "lights", "mode", "shading", "sampling", "clipping", "isosurface"}
        extra = set(d) - known
        if extra:
            raise ValueError(f"unknown Scene fields {sorted(extra)}; valid: {sorted(known)}")
        ref = d.get("volume", "") or ""
        if volume is None and resolve is not None and ref:
            volume = resolve(ref)
        kw: dict[str, Any] = {"volume": volume, "volume_ref": ref}
        if "transfer" in d:
            kw["transfer"] = TransferFunction.from_dict(d["transfer"])
        if "lights" in d:
            kw["lights"] = tuple(Light.from_dict(x) for x in d["lights"])
        if "mode" in d:
            kw["mode"] = d["mode"]
        for name, sub in (("shading", Shading), ("sampling", Sampling), ("clipping", Clipping),
                          ("isosurface", Isosurface)):
            if name in d:
                kw[name] = sub.from_dict(d[name])
        return cls(**kw)

    def to_json(self, **kw) -> str:
        return json.dumps(self.to_dict(), **kw)

    @classmethod
    def from_json(cls, text: str, *, volume=None, resolve: Callable[[str], Any] | None = None) -> "Scene":
        return cls.from_dict(json.loads(text), volume=volume, resolve=resolve)
