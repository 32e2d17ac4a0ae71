"""Rendering a flythrough: the endoscopic scene, a flashlight on the camera, frames and their timing log.

An :class:`Endoscope` holds everything that decides the pictures except the
pose: the volume, how the wall looks (``mode`` ``"isosurface"`` at the wall
threshold, the classic surface view of virtual endoscopy, or ``"composite"``
with a transfer function), the shading, the camera's field of view and near
plane, and the lights. With ``shading="phong"`` a spot light rides on the
camera (a flashlight at the eye, along the view) next to any world lights;
``"headlight"`` uses the renderer's point light at the eye; ``"none"`` is unlit.

Frames are rendered by :func:`volumen.render.render` and timed; a
:class:`FrameLog` reports the mean frame time and the frame-time-weighted mean
``sum t^2 / sum t`` (the time a frame picked at a random moment of the run
took: it weighs the slow frames the viewer waits on).
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass, field, replace

import numpy as np

from ...core import Display, Isosurface, Light, Sampling, Scene, Shading, TransferFunction

__all__ = ["Endoscope", "FrameLog", "ENDOSCOPY_PRESETS", "endoscopy_transfer"]

# Transfer functions for looking at a lumen's wall from inside (HU). Opacity per voxel step.
ENDOSCOPY_PRESETS = {
    # air-filled lumen (colon, airway): transparent air, the wall opaque from about -500 HU
    "endo-air": (((-1024, 0.8, 0.45, 0.4), (-600, 0.85, 0.5, 0.45), (-300, 0.95, 0.65, 0.58), (200, 1.0, 0.8, 0.7),
                  (3071, 1, 1, 1)),
                 ((-1024, 0.0), (-650, 0.0), (-450, 1.0), (3071, 1.0))),
    # contrast-filled lumen (vessels, ~300 HU): transparent contrast, the wall opaque below ~120 HU
    "endo-contrast": (((-1024, 0.7, 0.2, 0.2), (60, 0.85, 0.35, 0.3), (200, 0.95, 0.6, 0.5), (3071, 1, 1, 1)),
                      ((-1024, 1.0), (100, 1.0), (160, 0.0), (3071, 0.0))),
}


def endoscopy_transfer(name: str, volume=None) -> TransferFunction:
    """A transfer function by name: one of :data:`ENDOSCOPY_PRESETS` or of ``volumen.core.PRESETS`` (fitted to
    ``volume``: ``core.fitted_preset``; a data-relative one needs it)."""
    from ...core import PRESETS, fitted_preset

    if name in ENDOSCOPY_PRESETS:
        color, opacity = ENDOSCOPY_PRESETS[name]
        return TransferFunction(color=color, opacity=opacity, name=name)
    if name in PRESETS:
        return TransferFunction.preset(name) if volume is None else fitted_preset(name, volume)
    raise ValueError(f"unknown preset {name!r}; valid: {', '.join([*ENDOSCOPY_PRESETS, *PRESETS])}")


@dataclass
class FrameLog:
    """Per-frame render times (s).

    ``mean`` is the plain mean; ``weighted_mean`` = ``sum t^2 / sum t``.
    """

    times: list[float] = field(default_factory=list)

    def add(self, seconds: float) -> None:
        self.times.append(float(seconds))

    @property
    def mean(self) -> float:
        return float(np.mean(self.times)) if self.times else float("nan")

    @property
    def weighted_mean(self) -> float:
        t = np.asarray(self.times, float)
        return float(np.sum(t * t) / np.sum(t)) if t.size and t.sum() > 0 else float("nan")

    def to_dict(self) -> dict:
        """``frames``, ``mean_s``, ``weighted_mean_s`` (sum t^2 / sum t), ``total_s``, ``min_s``, ``max_s``,
        ``times_s``."""
        t = self.times
        return {"frames": len(t), "mean_s": self.mean, "weighted_mean_s": self.weighted_mean,
                "total_s": float(np.sum(t)) if t else 0.0, "min_s": min(t) if t else None,
                "max_s": max(t) if t else None, "times_s": list(t)}

    def save(self, path) -> None:
        """Write :meth:`to_dict` as JSON."""
        from pathlib import Path

        Path(path).write_text(json.dumps(self.to_dict(), indent=1))


@dataclass(frozen=True, kw_only=True)
class Endoscope:
    """How an endoscopic flythrough is drawn (everything but the pose).

    Parameters
    ----------
    volume : Volume
    mode : {"isosurface", "composite"}
        Surface at ``threshold`` or direct volume rendering with ``transfer``.
    threshold : float, data units
        The wall's value for the isosurface (-500 HU for air lumens).
    transfer : TransferFunction or None
        For composite (default: ``endo-air``).
    color : (3,) float
        Linear RGB of the isosurface (mucosa pink by default).
    shading : one of ``volumen.core.SHADINGS``
        ``none`` and ``headlight`` as in the ray caster; every lit model (``phong``,
        ``shadows``, ``scattering``, ``pathtrace``) puts a flashlight on the camera
        in addition to ``lights``.
    flashlight : float
        Spot exponent of the flashlight (0: a point light at the eye).
    falloff : float, mm
        The flashlight's reach: what a pixel shows at depth ``d`` beyond it is dimmed by
        ``(falloff / d) ** 2`` (a lamp's inverse-square fall-off, not applied nearer than
        ``falloff``; the renderers' lights themselves do not fall off). It is the picture's depth
        cue: the near wall bright, the lumen ahead dark, so a bifurcation (the carina) reads as a
        ridge between two dark openings. 0 (the default): no fall-off; :func:`make_flight` sets
        three times the lumen's median radius.
    lights : tuple of Light
        World lights (used with ``phong``).
    fov : float, degrees
        Vertical field of view (30..140).
    near : float, mm
        Near plane ahead of the eye.
    samples_per_voxel : float
        Sampling density of the rays.
    interpolation : one of ``volumen.core.INTERPOLATIONS``
        The reconstruction between voxels (``Sampling.interpolation``): ``"bspline"`` smooths away the
        terraces trilinear reconstruction leaves on the wall of a thick-slice scan.
    jitter : bool or None
        Offset each ray's first sample by a hash of its pixel (the same in every
        frame): breaks the concentric "wood-grain" rings of a camera looking down
        a tube into fine noise fixed on the screen, which does not crawl in motion.
        None (default): on in composite mode, off in isosurface mode (whose
        refined hits show no rings).
    display : Display
        How the frames' radiance becomes display values. Default: linear, no exposure: the
        flashlight's ``falloff`` is the picture's depth cue (near wall bright, far lumen dark),
        which a metered exposure would lift away (a milky, flat picture).
    """

    volume: object = field(repr=False)
    mode: str = "isosurface"
    threshold: float = -500.0
    transfer: TransferFunction | None = None
    color: tuple[float, float, float] = (0.93, 0.6, 0.52)
    shading: str = "phong"
    flashlight: float = 2.0
    falloff: float = 0.0
    lights: tuple[Light, ...] = ()
    fov: float = 100.0
    near: float = 0.5
    samples_per_voxel: float = 2.0
    interpolation: str = "linear"
    jitter: bool | None = None
    display: Display = field(default_factory=lambda: Display(tonemap="linear"))

    def __post_init__(self):
        if self.mode not in ("isosurface", "composite"):
            raise ValueError(f"mode must be 'isosurface' or 'composite', got {self.mode!r}")
        from ...core import INTERPOLATIONS, SHADINGS

        if self.interpolation not in INTERPOLATIONS:
            raise ValueError(f"interpolation must be one of {', '.join(map(repr, INTERPOLATIONS))}; "
                             f"got {self.interpolation!r}")
        if self.shading not in SHADINGS:
            raise ValueError(f"shading must be one of {', '.join(map(repr, SHADINGS))}; got {self.shading!r}")
        if not 30.0 <= self.fov <= 140.0:
            raise ValueError(f"fov must be within [30, 140] degrees for endoscopy, got {self.fov}")
        if not (np.isfinite(self.near) and self.near >= 0):
            raise ValueError(f"near must be >= 0 mm, got {self.near}")
        if not (np.isfinite(self.falloff) and self.falloff >= 0):
            raise ValueError(f"falloff must be >= 0 mm, got {self.falloff}")
        if self.transfer is None:
            object.__setattr__(self, "transfer", endoscopy_transfer("endo-air"))
        object.__setattr__(self, "lights", tuple(self.lights))
        if self.jitter is None:
            object.__setattr__(self, "jitter", self.mode == "composite")

    def with_(self, **changes) -> Endoscope:
        """A copy with ``changes``; a new ``mode`` without ``jitter`` takes that mode's default jitter."""
        if "mode" in changes and "jitter" not in changes:
            changes["jitter"] = None
        return replace(self, **changes)

    def to_dict(self) -> dict:
        """Every setting but the volume, JSON-ready (the transfer function and lights as their dicts)."""
        return {"mode": self.mode, "threshold": self.threshold, "transfer": self.transfer.to_dict(),
                "color": list(self.color), "shading": self.shading, "flashlight": self.flashlight,
                "falloff": self.falloff, "lights": [light.to_dict() for light in self.lights], "fov": self.fov,
                "near": self.near, "samples_per_voxel": self.samples_per_voxel, "interpolation": self.interpolation,
                "jitter": self.jitter, "display": self.display.to_dict()}

    @classmethod
    def from_dict(cls, d: dict, volume) -> Endoscope:
        """Inverse of :meth:`to_dict` on ``volume``; unknown keys raise ValueError naming the valid ones."""
        known = {f for f in cls.__dataclass_fields__ if f != "volume"}
        extra = set(d) - known
        if extra:
            raise ValueError(f"unknown Endoscope fields {sorted(extra)}; valid: {sorted(known)}")
        d = dict(d)
        if "transfer" in d:
            d["transfer"] = TransferFunction.from_dict(d["transfer"])
        d["lights"] = tuple(Light.from_dict(x) for x in d.get("lights", ()))
        if "color" in d:
            d["color"] = tuple(d["color"])
        if "display" in d:
            d["display"] = Display.from_dict(d["display"])
        return cls(volume=volume, **d)

    def scene(self, pose) -> Scene:
        """The :class:`Scene` seen from ``pose`` (the flashlight sits at the eye)."""
        lights = self.lights
        if self.shading not in ("none", "headlight"):
            lights = (Light(position=pose.position, direction=pose.forward, exponent=self.flashlight), *lights)
        return Scene(volume=self.volume, transfer=self.transfer, mode=self.mode, lights=lights,
                     shading=Shading(mode=self.shading),
                     sampling=Sampling(samples_per_voxel=self.samples_per_voxel, interpolation=self.interpolation,
                                       jitter=self.jitter, seed=0),
                     isosurface=Isosurface(value=self.threshold, color=self.color), display=self.display)

    def camera(self, pose):
        """The endoscopic camera at ``pose``."""
        return pose.camera(fov=self.fov, near=self.near)

    def render(self, pose, size: tuple[int, int] = (256, 256)):
        """One frame: :class:`~volumen.core.Image` of ``size = (width, height)`` seen from ``pose``."""
        from ...render import render

        img = render(self.scene(pose), self.camera(pose), size)
        if self.falloff > 0 and self.shading != "none":
            d = np.where(np.isfinite(img.depth), img.depth, np.inf)
            img.rgba[..., :3] *= np.minimum(1.0, (self.falloff / np.maximum(d, 1e-6)) ** 2)[..., None]
        return img

    def frames(self, poses, size: tuple[int, int] = (256, 256), *, log: FrameLog | None = None,
               progress: bool = False, desc: str = "frames"):
        """Render ``poses`` one after the other, yielding Images; times each into ``log``.

        ``progress`` shows a tqdm bar on stderr.
        """
        it = poses
        if progress:
            from tqdm import tqdm

            it = tqdm(poses, desc=desc, unit="frame")
        for pose in it:
            t = time.perf_counter()
            img = self.render(pose, size)
            if log is not None:
                log.add(time.perf_counter() - t)
            yield img
