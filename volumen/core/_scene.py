"""What a picture shows: the Scene and its settings, all plain data that round-trips through JSON.

A :class:`Scene` holds the :class:`~volumen.core.Volume` object at run time,
but its JSON holds only ``volume_ref``, a string naming where the volume comes
from (a file path, or a phantom name such as ``"phantom:head"``). Resolving
that string is the caller's job (the command line and the application pass a
``resolve`` function to :meth:`Scene.from_dict`), so ``core`` never reads files.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any, Literal, get_args

import numpy as np

from ._environment_light import Environment
from ._jsondata import JsonData, _choice, _vec
from ._lighting import LIGHT_KINDS, SHADINGS, Light, LightKind, Shading, ShadingMode
from ._tonemap import Display
from ._transfer import TransferFunction, default_preset
from ._volume import is_chunked

__all__ = ["Light", "LightKind", "LIGHT_KINDS", "Shading", "Sampling", "ClipPlane", "Clipping", "Isosurface", "Scene",
           "Mode", "ShadingMode", "MODES", "SHADINGS", "Interpolation", "INTERPOLATIONS", "ADAPTIVE_SHADINGS",
           "adaptive_on"]

Mode = Literal["composite", "mip", "minip", "average", "isosurface"]
MODES: tuple[str, ...] = get_args(Mode)
Interpolation = Literal["linear", "nearest", "bspline"]
#: the reconstructions of ``Sampling.interpolation``
INTERPOLATIONS: tuple[str, ...] = get_args(Interpolation)
#: the shading models adaptive sampling is on for by default (``Sampling.adaptive`` None): their light does not
#: change along a sample's longer step
ADAPTIVE_SHADINGS = ("none", "headlight", "phong")


@dataclass(frozen=True, kw_only=True)
class Sampling(JsonData):
    """How rays sample the volume.

    Parameters
    ----------
    samples_per_voxel : float
        Step ``ds = ds0 / samples_per_voxel`` with ``ds0`` the smallest voxel spacing (mm).
    interpolation : {"linear", "nearest", "bspline"}
        The reconstruction between voxel centres: trilinear, the nearest voxel, or the tricubic B-spline
        (approximating: it smooths, about a third of a voxel's variance per axis, and takes the scan's slices
        away, the terraces trilinear shows on surfaces of thick-slice scans; values and gradients on every
        device; 3-4x the trilinear time per sample, see ``render/raycast/_bspline.py``).
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
    adaptive : bool or None
        Adaptive sampling (composite mode with skipping, post-classified, no labels): in the blocks where every
        value classifies nearly transparent (below 0.1 opacity per step), one sample stands for up to 4 steps,
        its opacity corrected to their length; full rate wherever a block holds anything more opaque. Faster
        on translucent presets (soft tissue in every ray); pictures within a mean 0.005 of full-rate sampling.
        ``None``, the default: on for the shading models whose light is the same along those longer steps
        (:data:`ADAPTIVE_SHADINGS`: none, headlight, phong), off for shadows, scattering and path tracing,
        whose light changes along them (a homogeneous scattering slab came out 1.7-5.5 % off its closed form
        with it, 0.03 % without); ``True``: on for every model; ``False``: the exact full-rate picture
        (:func:`adaptive_on` says which a scene gets). Drawn in memory on the CPU and CUDA devices; bricks drawn
        out of core, and OpenGL, sample at full rate.
    preintegrate : bool
        Pre-integrated classification (composite mode).
    lattice : bool
        Sample every ray at ``t = (m + jitter) * ds`` from its origin (m whole,
        entry <= t < exit), each sample standing for a full step, instead of
        from the ray's entry: the samples fall at the same points whatever box
        is drawn, so bricks of a volume drawn one by one and composited equal
        the whole volume drawn at once (:mod:`volumen.render.bricked`).
    """

    samples_per_voxel: float = 1.0
    interpolation: Interpolation = "linear"
    jitter: bool = True
    seed: int = 0
    early_termination: float = 0.99
    skip_empty: bool = True
    block_size: int = 4
    adaptive: bool | None = None
    preintegrate: bool = False
    lattice: bool = False

    def __post_init__(self) -> None:
        if not (np.isfinite(self.samples_per_voxel) and 0.01 <= self.samples_per_voxel <= 64):
            raise ValueError(f"samples_per_voxel must be in [0.01, 64], got {self.samples_per_voxel}")
        object.__setattr__(self, "samples_per_voxel", float(self.samples_per_voxel))
        _choice("Sampling.interpolation", self.interpolation, INTERPOLATIONS)
        if not 0.0 < self.early_termination <= 1.0:
            raise ValueError(f"early_termination must be in (0, 1], got {self.early_termination}")
        object.__setattr__(self, "early_termination", float(self.early_termination))
        if not (isinstance(self.block_size, (int, np.integer)) and 2 <= self.block_size <= 64):
            raise ValueError(f"block_size must be an integer in [2, 64], got {self.block_size!r}")
        object.__setattr__(self, "block_size", int(self.block_size))
        object.__setattr__(self, "seed", int(self.seed))
        object.__setattr__(self, "adaptive", None if self.adaptive is None else bool(self.adaptive))
        object.__setattr__(self, "jitter", bool(self.jitter))
        object.__setattr__(self, "skip_empty", bool(self.skip_empty))
        object.__setattr__(self, "preintegrate", bool(self.preintegrate))
        object.__setattr__(self, "lattice", bool(self.lattice))


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


def _first_transfer(volume, mode: str) -> TransferFunction:
    """The transfer function of a scene made without one: the volume's default preset (in memory), else the ramp."""
    if volume is None or is_chunked(volume.data):
        return TransferFunction()
    return default_preset(volume, mode)


@dataclass(frozen=True, kw_only=True)
class Scene:
    """Everything but the camera that decides a picture.

    Parameters
    ----------
    volume : Volume or None
        The data, at run time; not part of equality nor of the JSON.
    volume_ref : str
        Where the volume comes from (a path or ``"phantom:NAME"``); written to JSON.
    transfer : TransferFunction, optional
        Default: the volume's default preset for the mode (:func:`default_preset`: ``ct-skin-bone`` on a CT's
        values, ``mr-default`` over another scan's display range, ``mip-gray`` for the projections), so a scene
        made with a volume alone shows its anatomy; the plain 0..1 ramp without a volume, or with a chunked one
        (choosing would read its chunks).
    lights : sequence of Light
        Used by the shading modes ``phong``, ``shadows``, ``scattering`` and
        ``pathtrace`` (any number).
    mode : {"composite", "mip", "minip", "average", "isosurface"}
    shading, sampling, clipping, isosurface :
        The settings dataclasses.
    labels : LabelLayer or None
        Structures classifying the samples (composite mode), at run time; not part of equality nor of the JSON.
    environment : Environment
        The light around the volume (the lit models' ambient term, the path tracer's sky; the studio rig's
        lights when ``lights`` is empty).
    display : Display
        How the picture is shown: exposure, tone curve, encoding (the rendered Image carries it).
    """

    volume: Any = field(default=None, compare=False, repr=False)
    volume_ref: str = ""
    transfer: TransferFunction | None = None
    lights: tuple[Light, ...] = ()
    mode: Mode = "composite"
    shading: Shading = field(default_factory=Shading)
    sampling: Sampling = field(default_factory=Sampling)
    clipping: Clipping = field(default_factory=Clipping)
    isosurface: Isosurface = field(default_factory=Isosurface)
    labels: Any = field(default=None, compare=False, repr=False)
    environment: Environment = field(default_factory=Environment)
    display: Display = field(default_factory=Display)

    def __post_init__(self) -> None:
        _choice("Scene.mode", self.mode, MODES)
        if self.transfer is None:
            object.__setattr__(self, "transfer", _first_transfer(self.volume, self.mode))
        object.__setattr__(self, "lights", tuple(self.lights))
        for name, cls in (("transfer", TransferFunction), ("shading", Shading), ("sampling", Sampling),
                          ("clipping", Clipping), ("isosurface", Isosurface), ("environment", Environment),
                          ("display", Display)):
            if not isinstance(getattr(self, name), cls):
                raise ValueError(f"Scene.{name} must be a {cls.__name__}, got {type(getattr(self, name)).__name__}")
        for light in self.lights:
            if not isinstance(light, Light):
                raise ValueError(f"Scene.lights must hold Light objects, got {type(light).__name__}")

    def with_(self, **changes) -> Scene:
        """A copy with some fields changed (validated again)."""
        return replace(self, **changes)

    def to_dict(self) -> dict:
        """JSON-ready dict; the volume appears only as ``volume`` = ``volume_ref``."""
        return {"volume": self.volume_ref, "transfer": self.transfer.to_dict(),
                "lights": [lt.to_dict() for lt in self.lights], "mode": self.mode,
                "shading": self.shading.to_dict(), "sampling": self.sampling.to_dict(),
                "clipping": self.clipping.to_dict(), "isosurface": self.isosurface.to_dict(),
                "environment": self.environment.to_dict(), "display": self.display.to_dict()}

    @classmethod
    def from_dict(cls, d: dict, *, volume=None, resolve: Callable[[str], Any] | None = None) -> Scene:
        """Inverse of :meth:`to_dict`.

        ``volume`` is attached as is; otherwise, when ``resolve`` is given, it
        is called with the stored reference string and must return the Volume.
        """
        known = {"volume", "transfer", "lights", "mode", "shading", "sampling", "clipping", "isosurface",
                 "environment", "display"}
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
                          ("isosurface", Isosurface), ("environment", Environment), ("display", Display)):
            if name in d:
                kw[name] = sub.from_dict(d[name])
        return cls(**kw)

    def to_json(self, **kw) -> str:
        return json.dumps(self.to_dict(), **kw)

    @classmethod
    def from_json(cls, text: str, *, volume=None, resolve: Callable[[str], Any] | None = None) -> Scene:
        return cls.from_dict(json.loads(text), volume=volume, resolve=resolve)


def adaptive_on(scene) -> bool:
    """Whether ``scene`` asks for adaptive sampling: ``Sampling.adaptive`` when set, else whether its shading
    model is one of :data:`ADAPTIVE_SHADINGS` (where it applies -- composite, skipping, post-classified, no
    labels -- the ray caster decides)."""
    asked = scene.sampling.adaptive
    return scene.shading.mode in ADAPTIVE_SHADINGS if asked is None else asked
