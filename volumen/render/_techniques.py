"""The one vocabulary of the renderers: *devices* (where a picture is computed) and *techniques* (how).

Every name is declared here once and read by the Python API (``render(...,
device=..., technique=..., **options)``), the command line (``--device``,
``--technique`` and one flag per technique option) and the application (its
device and technique boxes):

* :data:`DEVICES`: ``cpu`` (Numba), ``cuda`` (the same kernels on an NVIDIA
  GPU), ``gl`` (OpenGL: the rasterized techniques and a fragment-shader ray
  caster) and ``auto`` (the fastest usable here: :func:`choose_device`);
* :data:`TECHNIQUES`: ``raycast`` (ray casting; cpu, cuda, gl), ``slicing``
  (texture slicing; gl) and ``mesh`` (the isosurface as a marching-cubes mesh;
  gl), each with an options dataclass whose ``Literal`` fields are the choices
  the CLI and the app offer (:func:`option_choices`).

A :class:`Technique` is a name plus its options and round-trips through JSON
(:meth:`Technique.to_dict` / :meth:`Technique.from_dict`).
"""

from __future__ import annotations

import dataclasses
import typing
from collections.abc import Callable
from dataclasses import dataclass, field

from .raster._mesh import MeshOptions
from .raster._slicing import SlicingOptions

__all__ = ["DEVICES", "TECHNIQUES", "Technique", "TechniqueSpec", "RaycastOptions", "option_choices",
           "resolve_device", "choose_device", "legacy_backend"]

#: every device name; ``auto`` stands for the fastest usable here (:func:`choose_device`)
DEVICES: tuple[str, ...] = ("cpu", "cuda", "gl", "auto")


@dataclass(frozen=True, kw_only=True)
class RaycastOptions:
    """Ray casting takes its settings from the Scene (mode, shading, sampling); it has no technique options."""

    def to_dict(self) -> dict:
        return {}


def _raycast(scene, camera, size, device, options):
    if device == "cuda":
        from .cuda import render_cuda  # numba.cuda loads here, not at import

        return render_cuda(scene, camera, size)
    if device == "gl":
        from .raster import render_raycast_gl  # moderngl loads here, not at import

        return render_raycast_gl(scene, camera, size)
    from .raycast import render_cpu  # Numba loads here, not at import

    return render_cpu(scene, camera, size)


def _raycast_only(scene, technique: str) -> None:
    """The B-spline reconstruction is the ray caster's (its samples and gradients): a one-line error elsewhere."""
    if scene.sampling.interpolation == "bspline":
        from ..errors import DeviceLimitError

        raise DeviceLimitError(f"the B-spline reconstruction is drawn by the raycast technique (cpu, cuda, gl), "
                               f"not {technique}; use --technique raycast")


def _slicing(scene, camera, size, device, options):
    from .raster import render_slicing

    _raycast_only(scene, "slicing")

    return render_slicing(scene, camera, size, options)


def _mesh(scene, camera, size, device, options):
    from .raster import render_isosurface_mesh

    _raycast_only(scene, "mesh")

    return render_isosurface_mesh(scene, camera, size, options)


@dataclass(frozen=True)
class TechniqueSpec:
    """A registered technique: ``devices`` it runs on (the first is its default), its ``options`` class,
    and ``draw(scene, camera, size, device, options) -> Image``."""

    name: str
    devices: tuple[str, ...]
    options: type
    draw: Callable
    description: str


#: technique name -> TechniqueSpec (the only registry of renderers)
TECHNIQUES: dict[str, TechniqueSpec] = {t.name: t for t in (
    TechniqueSpec("raycast", ("cpu", "cuda", "gl"), RaycastOptions, _raycast,
                  "ray casting: every mode and shading model of the Scene"),
    TechniqueSpec("slicing", ("gl",), SlicingOptions, _slicing,
                  "texture slicing: view-aligned planes through a 3-D texture (composite mode)"),
    TechniqueSpec("mesh", ("gl",), MeshOptions, _mesh,
                  "the isosurface as a marching-cubes mesh drawn by OpenGL"),
)}


def _spec(name: str) -> TechniqueSpec:
    if name not in TECHNIQUES:
        raise ValueError(f"unknown technique {name!r}; valid: {', '.join(TECHNIQUES)}")
    return TECHNIQUES[name]


def option_choices(name: str) -> dict[str, tuple | type]:
    """The options of technique ``name``: field -> its choices (a ``Literal`` field) or its type (bool, int)."""
    cls = _spec(name).options
    hints = typing.get_type_hints(cls)
    return {f.name: (typing.get_args(hints[f.name]) or hints[f.name]) for f in dataclasses.fields(cls)}


@dataclass(frozen=True)
class Technique:
    """A technique name and its options (``Technique("slicing", precision="uint8")``).

    Parameters
    ----------
    name : one of :data:`TECHNIQUES`
    options : the technique's options dataclass, or keywords for it (its defaults when none given)
    """

    name: str = "raycast"
    options: object = field(default=None)

    def __init__(self, name: str = "raycast", options=None, **kw):
        cls = _spec(name).options
        if options is None:
            options = cls()
        elif not isinstance(options, cls):
            raise ValueError(f"technique {name!r} takes {cls.__name__}, got {type(options).__name__}")
        if kw:
            valid = [f.name for f in dataclasses.fields(cls)]
            bad = [k for k in kw if k not in valid]
            if bad:
                raise ValueError(f"technique {name!r} has no option {bad[0]!r}; valid: {', '.join(valid) or 'none'}")
            options = dataclasses.replace(options, **kw)
        object.__setattr__(self, "name", name)
        object.__setattr__(self, "options", options)

    @property
    def spec(self) -> TechniqueSpec:
        return TECHNIQUES[self.name]

    def to_dict(self) -> dict:
        return {"name": self.name, "options": self.options.to_dict()}

    @classmethod
    def from_dict(cls, d: dict) -> Technique:
        if not isinstance(d, dict) or set(d) - {"name", "options"}:
            raise ValueError(f"a technique is {{'name': ..., 'options': {{...}}}}, got {d!r}")
        return cls(d.get("name", "raycast"), **d.get("options", {}))


def choose_device(device: str | None, technique: str = "raycast") -> tuple[str, str]:
    """``(device, why)``: where ``technique`` runs and a short reason, for ``device`` None (the technique's
    default: ``cpu`` for raycast, ``gl`` for slicing and mesh), a name, or ``auto`` -- the fastest usable here.

    For ray casting ``auto`` is ``cuda`` where a CUDA device is usable (never the simulator), else ``gl`` when
    OpenGL runs on a hardware renderer, else ``cpu``: Mesa's llvmpipe / softpipe and SwiftShader rasterize on
    the CPU and are slower than the CPU ray caster (18x on a 164x126x120 CT at 352x345). Slicing and mesh run
    on ``gl`` only. Raises ValueError for a name not in :data:`DEVICES` or one the technique cannot use.
    """
    spec = _spec(technique)
    if device is None:
        return spec.devices[0], f"the default device of {technique}"
    if device not in DEVICES:
        raise ValueError(f"unknown device {device!r}; valid: {', '.join(DEVICES)}")
    if device != "auto":
        if device not in spec.devices:
            raise ValueError(f"technique {technique!r} runs on {', '.join(spec.devices)} (or auto), not {device!r}")
        return device, "asked for"
    if spec.devices == ("gl",):
        return "gl", f"{technique} runs on OpenGL only"
    if "cuda" in spec.devices:
        from .cuda import cuda_available  # numba.cuda loads here, not at import

        if cuda_available():
            return "cuda", "a CUDA device is usable"
    if "gl" in spec.devices:
        from .raster import RasterUnavailable, gl_renderer  # moderngl loads here, not at import

        try:
            renderer, hardware = gl_renderer()
        except RasterUnavailable:
            return "cpu", "no CUDA device and no OpenGL here"
        if hardware:
            return "gl", f"no CUDA device; OpenGL runs on {renderer}"
        return "cpu", f"no CUDA device; OpenGL is {renderer}, a software renderer slower than the CPU ray caster"
    return spec.devices[0], f"the default device of {technique}"


def resolve_device(device: str | None, technique: str = "raycast") -> str:
    """The device ``technique`` runs on (:func:`choose_device` without the reason)."""
    return choose_device(device, technique)[0]


#: the deprecated ``backend=`` names of volumen 0.1 -> (device, technique name, options)
_LEGACY = {
    "cpu": ("cpu", "raycast", {}), "cuda": ("cuda", "raycast", {}), "auto": ("auto", "raycast", {}),
    "slicing": ("gl", "slicing", {}), "slicing-front-to-back": ("gl", "slicing", {"order": "front-to-back"}),
    "slicing-pre": ("gl", "slicing", {"classification": "pre"}),
    "slicing-uint8": ("gl", "slicing", {"precision": "uint8"}),
    "slicing-float16": ("gl", "slicing", {"precision": "float16"}),
    **{f"slicing-{p}": ("gl", "slicing", {"planes": p})
       for p in ("near-quarter", "diagonal-quarter", "two-per-voxel", "two-then-one")},
    "mesh": ("gl", "mesh", {}), "mesh-gouraud": ("gl", "mesh", {"shading": "gouraud"}),
}


def legacy_backend(backend: str) -> tuple[str, Technique]:
    """``(device, Technique)`` for a backend name of volumen 0.1 (``"cpu"``, ``"slicing-uint8"``,
    ``"mesh-gouraud"``...): reads old settings files and sessions."""
    if backend not in _LEGACY:
        raise ValueError(f"unknown backend {backend!r}; valid: {', '.join(_LEGACY)}")
    device, name, options = _LEGACY[backend]
    return device, Technique(name, **options)
