"""Stereo output for headsets and 3D displays: the two eye cameras and how their pictures are combined.

Plain numpy. ``side-by-side`` puts the left eye's picture in the left half
(each eye rendered at half the width, as head-mounted displays and 3D TVs
expect); ``anaglyph`` takes red from the left eye and green and blue from the
right eye (red-cyan glasses).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Literal, get_args

import numpy as np

from ..core import Camera

__all__ = ["Stereo", "STEREO_MODES", "eye_cameras", "eye_size", "combine"]

StereoMode = Literal["off", "side-by-side", "anaglyph"]
STEREO_MODES: tuple[str, ...] = get_args(StereoMode)


@dataclass(frozen=True, kw_only=True)
class Stereo:
    """Stereo settings.

    Parameters
    ----------
    mode : {"off", "side-by-side", "anaglyph"}
    eye_separation : float, mm
        Distance between the two eyes (world mm; larger looks deeper).
    convergence : float or None, mm
        Distance from the eyes to the plane of zero parallax (the eyes turn
        toward the point this far ahead); None: the camera's target distance.
    """

    mode: StereoMode = "off"
    eye_separation: float = 20.0
    convergence: float | None = None

    def __post_init__(self) -> None:
        if self.mode not in STEREO_MODES:
            raise ValueError(f"stereo mode must be one of {', '.join(STEREO_MODES)}, got {self.mode!r}")
        if not (np.isfinite(self.eye_separation) and self.eye_separation >= 0):
            raise ValueError(f"eye_separation must be >= 0 mm, got {self.eye_separation}")
        if self.convergence is not None and not (np.isfinite(self.convergence) and self.convergence > 0):
            raise ValueError(f"convergence must be None or > 0 mm, got {self.convergence}")

    def to_dict(self) -> dict:
        return asdict(self)

    @classmethod
    def from_dict(cls, d: dict) -> Stereo:
        extra = set(d) - {"mode", "eye_separation", "convergence"}
        if extra:
            raise ValueError(f"unknown stereo fields {sorted(extra)}")
        return cls(**d)


def eye_cameras(camera: Camera, stereo: Stereo) -> list[Camera]:
    """``[camera]`` when stereo is off, else ``[left, right]``.

    The eyes sit ``eye_separation / 2`` mm to each side along the camera's
    right axis and both look at the convergence point, ``convergence`` mm ahead
    of the centre eye (toe-in), keeping the camera's up.
    """
    if stereo.mode == "off":
        return [camera]
    r, _u, f = camera.basis()
    eye = np.asarray(camera.position, float)
    dist = stereo.convergence if stereo.convergence is not None else camera.distance
    focus = eye + f * dist
    half = 0.5 * stereo.eye_separation * r
    return [camera.with_(position=tuple(eye - half), target=tuple(focus)),
            camera.with_(position=tuple(eye + half), target=tuple(focus))]


def eye_size(size: tuple[int, int], stereo: Stereo) -> tuple[int, int]:
    """Pixels ``(width, height)`` each eye is rendered at for a picture of ``size``."""
    w, h = size
    return (max(1, w // 2), h) if stereo.mode == "side-by-side" else (w, h)


def combine(pictures: list[np.ndarray], stereo: Stereo, size: tuple[int, int]) -> np.ndarray:
    """Combine the eyes' uint8 RGB pictures ``(H, W, 3)`` into one ``(height, width, 3)`` picture of ``size``."""
    if stereo.mode == "off" or len(pictures) == 1:
        return pictures[0]
    left, right = pictures
    if stereo.mode == "anaglyph":
        out = right.copy()
        out[..., 0] = left[..., 0]
        return out
    w, h = size
    out = np.zeros((h, w, 3), np.uint8)
    out[:, :left.shape[1]] = left
    out[:, w - right.shape[1]:] = right
    return out
