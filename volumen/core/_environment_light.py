"""The environment light: what surrounds the volume (docs/design.md section 5), and the built-in studio rig.

An :class:`Environment` is part of the lighting settings of a :class:`~volumen.core.Scene`. The path tracer
importance-samples it; the other lit models (``phong``, ``shadows``, ``scattering``) take it as their ambient
term. Kinds:

* ``uniform``: a white environment of radiance ``Shading.phong.ambient`` (volumen's ambient term before the
  environment existed, exactly);
* ``studio``: a soft sky gradient (:func:`studio_sky`) around the camera's up axis and, when the scene has no
  lights of its own, the rig's key, fill and rim lights (:func:`studio_lights`), placed about the volume
  relative to the camera, so the subject is lit from the upper left front whatever the view;
* ``map``: an equirectangular HDR picture (``.hdr`` / ``.exr``, read by ``volumen.io.read_environment``; its
  pixels at run time in ``image``), world-fixed: its top is the patient's superior (+z), its centre column
  looks toward -y (the patient's posterior, so an anterior view sees the middle of the map behind the subject);
* ``auto`` (default): ``studio`` when the scene has no lights, ``uniform`` when it has (older scene files keep
  their pictures).

All radiance is linear RGB; ``intensity`` scales the sky or the map and the rig's lights together.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import Any, Literal, get_args

import numpy as np

from ._jsondata import JsonData, _choice, _nonneg
from ._lighting import Light

__all__ = ["Environment", "EnvironmentKind", "ENVIRONMENTS", "studio_lights", "studio_sky", "STUDIO_LIGHTS"]

EnvironmentKind = Literal["auto", "uniform", "studio", "map"]
ENVIRONMENTS: tuple[str, ...] = get_args(EnvironmentKind)

#: the studio rig's lights: name -> (direction from the volume's centre toward the light along the camera's
#: (right, up, back-toward-the-eye) axes, intensity, linear colour); a key light from the upper left front, a cooler
#: fill from the right, a rim light from behind and above that outlines the subject
STUDIO_LIGHTS = {
    "key": ((-0.55, 0.6, 0.6), 1.0, (1.0, 0.95, 0.88)),
    "fill": ((0.85, 0.05, 0.5), 0.3, (0.85, 0.9, 1.0)),
    "rim": ((0.25, 0.55, -0.8), 0.5, (1.0, 1.0, 1.0)),
}
#: distance of the rig's lights from the volume's centre and their radius (path tracer: soft shadows), in
#: volume diagonals
STUDIO_DISTANCE, STUDIO_RADIUS = 2.0, 0.25
#: the sky gradient: radiance straight up, at the horizon and straight down (linear RGB)
SKY_ZENITH, SKY_HORIZON, SKY_GROUND = (0.42, 0.46, 0.52), (0.34, 0.34, 0.34), (0.12, 0.11, 0.10)


@dataclass(frozen=True, kw_only=True)
class Environment(JsonData):
    """The light around the volume (see the module).

    Parameters
    ----------
    kind : {"auto", "uniform", "studio", "map"}
    map : str
        File of the ``map`` kind (an equirectangular ``.hdr`` or ``.exr``); the caller reads it into ``image``
        (``volumen.io.read_environment``), as it resolves ``Scene.volume_ref``.
    intensity : float >= 0
        Scales the sky (or the map) and the studio rig's lights.
    rotation : float, degrees
        Turns the sky or the map about its up axis.
    image : (H, W, 3) float32 or None
        The map's linear radiance at run time (row 0 the zenith); not part of the JSON nor of equality.
    """

    kind: EnvironmentKind = "auto"
    map: str = ""
    intensity: float = 1.0
    rotation: float = 0.0
    image: Any = field(default=None, compare=False, repr=False)

    def __post_init__(self) -> None:
        _choice("Environment.kind", self.kind, ENVIRONMENTS)
        object.__setattr__(self, "intensity", _nonneg("Environment.intensity", self.intensity))
        if not np.isfinite(float(self.rotation)):
            raise ValueError(f"Environment.rotation must be finite degrees, got {self.rotation!r}")
        object.__setattr__(self, "rotation", float(self.rotation))
        object.__setattr__(self, "map", str(self.map))
        if self.image is not None:
            img = np.asarray(self.image, dtype=np.float32)
            if img.ndim != 3 or img.shape[2] != 3 or min(img.shape[:2]) < 2 or not np.all(np.isfinite(img)):
                raise ValueError(f"Environment.image must be finite (H, W, 3) radiance, got shape {img.shape}")
            object.__setattr__(self, "image", np.maximum(img, 0.0))
        if self.kind == "map" and self.image is None and not self.map:
            raise ValueError("Environment kind 'map' needs a map file (Environment(kind='map', map='sky.hdr'))")

    def to_dict(self) -> dict:
        """JSON-ready dict; the map appears as its file name only."""
        return {f.name: getattr(self, f.name) for f in fields(self) if f.name != "image"}

    def resolved(self, has_lights: bool) -> Environment:
        """``auto`` made concrete: ``studio`` without scene lights, ``uniform`` with."""
        if self.kind != "auto":
            return self
        return Environment(kind="uniform" if has_lights else "studio", intensity=self.intensity,
                           rotation=self.rotation)


def studio_sky(up: np.ndarray) -> np.ndarray:
    """Radiance ``(..., 3)`` of the studio sky seen along unit directions whose up components are ``up``
    (``(...)``, in [-1, 1]): zenith to horizon smoothly above, horizon to ground below."""
    u = np.clip(np.asarray(up, dtype=np.float64), -1.0, 1.0)[..., None]
    zen, hor, gnd = (np.asarray(c, np.float64) for c in (SKY_ZENITH, SKY_HORIZON, SKY_GROUND))
    above = hor + (zen - hor) * np.sqrt(np.maximum(u, 0.0))
    below = hor + (gnd - hor) * np.sqrt(np.maximum(-u, 0.0))
    return np.where(u >= 0.0, above, below)


def studio_lights(camera, center, diagonal: float, intensity: float = 1.0) -> tuple[Light, ...]:
    """The studio rig's lights (:data:`STUDIO_LIGHTS`) for a volume of ``center`` (world mm) and ``diagonal``
    (mm) seen by ``camera``: point lights of radius ``STUDIO_RADIUS * diagonal`` at ``STUDIO_DISTANCE``
    diagonals from the centre, in world space."""
    r, u, f = camera.basis()
    c = np.asarray(center, dtype=float)
    out = []
    for d, power, color in STUDIO_LIGHTS.values():
        v = d[0] * r + d[1] * u - d[2] * f
        v = v / np.linalg.norm(v)
        out.append(Light(position=tuple(c + STUDIO_DISTANCE * diagonal * v), direction=tuple(-v),
                         intensity=power * intensity, color=color, kind="point",
                         radius=STUDIO_RADIUS * diagonal))
    return tuple(out)
