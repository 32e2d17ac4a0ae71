"""Automatic navigation: keyframes interpolated smoothly, played forward or backward, saved as JSON.

Positions follow a centripetal Catmull-Rom spline through the keyframes
(alpha = 0.5: no cusps nor self-intersections within a segment; Yuksel et al.
2011), with the end segments closed by mirrored phantom points. Orientations
are slerped between consecutive keyframes with the same local parameter.
Playback runs at constant speed along the curve: frame times are spread evenly
over ``[0, duration]`` and mapped to the spline parameter through a table of
arc length. Backward playback evaluates the same times in reverse order, so
its poses are exactly the forward ones reversed.
"""

from __future__ import annotations

import json
from dataclasses import dataclass

import numpy as np

from ._pose import Pose, slerp

__all__ = ["Keyframe", "KeyframePath", "catmull_rom"]

_TABLE = 64  # arc-length table samples per segment


def _vec(name, v) -> tuple[float, float, float]:
    a = np.asarray(v, float).reshape(-1)
    if a.shape != (3,) or not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be three finite numbers (x, y, z), got {v!r}")
    return (float(a[0]), float(a[1]), float(a[2]))


@dataclass(frozen=True)
class Keyframe:
    """One keyframe: eye ``position`` (world mm), view ``direction`` and ``up`` (any length, kept as given)."""

    position: tuple[float, float, float]
    direction: tuple[float, float, float]
    up: tuple[float, float, float] = (0.0, 0.0, 1.0)

    def __post_init__(self):
        for name in ("position", "direction", "up"):
            object.__setattr__(self, name, _vec(f"Keyframe.{name}", getattr(self, name)))
        Pose(self.position, self.direction, self.up)  # validates: non-zero, not parallel

    @property
    def pose(self) -> Pose:
        return Pose(self.position, self.direction, self.up)

    def to_dict(self) -> dict:
        return {"position": list(self.position), "direction": list(self.direction), "up": list(self.up)}


def catmull_rom(p0, p1, p2, p3, u, alpha: float = 0.5) -> np.ndarray:
    """Point(s) of the Catmull-Rom segment from ``p1`` (u = 0) to ``p2`` (u = 1); ``alpha`` 0.5 = centripetal.

    Barry-Goldman pyramid on knots spaced ``|p_{i+1} - p_i| ** alpha``. ``u`` scalar or (n,); returns (3,) or (n, 3).
    """
    p0, p1, p2, p3 = (np.asarray(p, float) for p in (p0, p1, p2, p3))
    u = np.asarray(u, float)
    scalar = u.ndim == 0
    u = np.atleast_1d(u)[:, None]
    eps = 1e-9
    t0 = 0.0
    t1 = t0 + max(np.linalg.norm(p1 - p0), eps) ** alpha
    t2 = t1 + max(np.linalg.norm(p2 - p1), eps) ** alpha
    t3 = t2 + max(np.linalg.norm(p3 - p2), eps) ** alpha
    t = t1 + u * (t2 - t1)
    a1 = (t1 - t) / (t1 - t0) * p0 + (t - t0) / (t1 - t0) * p1
    a2 = (t2 - t) / (t2 - t1) * p1 + (t - t1) / (t2 - t1) * p2
    a3 = (t3 - t) / (t3 - t2) * p2 + (t - t2) / (t3 - t2) * p3
    b1 = (t2 - t) / (t2 - t0) * a1 + (t - t0) / (t2 - t0) * a2
    b2 = (t3 - t) / (t3 - t1) * a2 + (t - t1) / (t3 - t1) * a3
    c = (t2 - t) / (t2 - t1) * b1 + (t - t1) / (t2 - t1) * b2
    return c[0] if scalar else c


class KeyframePath:
    """A camera path through keyframes, played at ``speed`` mm/s.

    Parameters
    ----------
    keyframes : sequence of Keyframe (at least 2)
    speed : float, mm/s
        Playback speed along the curve (a path of pure rotations lasts one second per keyframe gap).
    """

    def __init__(self, keyframes, *, speed: float = 20.0):
        kfs = tuple(k if isinstance(k, Keyframe) else Keyframe(**k) for k in keyframes)
        if len(kfs) < 2:
            raise ValueError(f"a keyframe path needs at least 2 keyframes, got {len(kfs)}")
        if not (np.isfinite(speed) and speed > 0):
            raise ValueError(f"speed must be > 0 mm/s, got {speed}")
        self.keyframes = kfs
        self.speed = float(speed)
        pts = np.array([k.position for k in kfs])
        self._ext = np.concatenate([[2 * pts[0] - pts[1]], pts, [2 * pts[-1] - pts[-2]]])
        self._quats = [k.pose.quaternion() for k in kfs]
        n = len(kfs) - 1
        g = np.concatenate([i + np.linspace(0.0, 1.0, _TABLE, endpoint=False) for i in range(n)] + [[float(n)]])
        xyz = self.position_at(g)
        arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(xyz, axis=0), axis=1))])
        self._g, self._arc = g, arc

    # -- geometry -----------------------------------------------------------
    @property
    def length(self) -> float:
        """Arc length of the position curve, mm."""
        return float(self._arc[-1])

    @property
    def duration(self) -> float:
        """Playback time, s (``length / speed``; one second per gap when the eye does not move)."""
        return self.length / self.speed if self.length > 1e-9 else float(len(self.keyframes) - 1)

    def position_at(self, g) -> np.ndarray:
        """Position(s) at spline parameter ``g`` in [0, K - 1] (keyframe i at g = i), (..., 3) mm."""
        g = np.clip(np.asarray(g, float), 0.0, len(self.keyframes) - 1)
        flat = np.atleast_1d(g)
        seg = np.minimum(np.floor(flat).astype(int), len(self.keyframes) - 2)
        out = np.empty((flat.size, 3))
        e = self._ext
        for i in np.unique(seg):
            sel = seg == i
            out[sel] = catmull_rom(e[i], e[i + 1], e[i + 2], e[i + 3], flat[sel] - i)
        return out[0] if np.ndim(g) == 0 else out.reshape(np.shape(g) + (3,))

    def pose_at_parameter(self, g: float) -> Pose:
        """The pose at spline parameter ``g``: Catmull-Rom position, slerped orientation."""
        g = float(np.clip(g, 0.0, len(self.keyframes) - 1))
        i = min(int(np.floor(g)), len(self.keyframes) - 2)
        return Pose.from_quaternion(self.position_at(g), slerp(self._quats[i], self._quats[i + 1], g - i))

    def pose_at(self, time: float) -> Pose:
        """The pose at playback ``time`` (s, clipped to [0, duration])."""
        f = float(np.clip(time / self.duration, 0.0, 1.0)) if self.duration > 0 else 0.0
        if self.length > 1e-9:
            g = float(np.interp(f * self.length, self._arc, self._g))
        else:
            g = f * (len(self.keyframes) - 1)
        return self.pose_at_parameter(g)

    # -- playback -----------------------------------------------------------
    def times(self, fps: float | None = None, frames: int | None = None) -> np.ndarray:
        """Frame times (s) spread evenly over [0, duration]: ``frames`` of them, or ``duration * fps + 1``."""
        if frames is None:
            if fps is None or not fps > 0:
                raise ValueError("give fps > 0 or a frame count")
            frames = int(round(self.duration * fps)) + 1
        if frames < 2:
            raise ValueError(f"frames must be >= 2, got {frames}")
        return np.linspace(0.0, self.duration, int(frames))

    def play(self, fps: float | None = None, frames: int | None = None, *, reverse: bool = False) -> list[Pose]:
        """The poses of playback at ``fps`` (or ``frames`` poses); ``reverse`` plays from the end to the start."""
        t = self.times(fps, frames)
        return [self.pose_at(x) for x in (t[::-1] if reverse else t)]

    # -- construction -------------------------------------------------------
    @classmethod
    def from_centerline(cls, centerline, *, every: float = 10.0, look_ahead: float = 10.0, up=None,
                        speed: float = 20.0, start: float = 0.0, end: float | None = None) -> KeyframePath:
        """Keyframes sampled every ``every`` mm along a :class:`Centerline` between arc ``start`` and ``end`` (mm).

        The view looks ``look_ahead`` mm ahead along the path; ``up`` follows
        the rotation-minimizing frame started from ``up`` (default: the world
        axis least aligned with the first tangent), so the picture does not spin.
        """
        end = centerline.length if end is None else float(end)
        if not 0.0 <= start < end <= centerline.length + 1e-9:
            raise ValueError(f"need 0 <= start < end <= {centerline.length:.1f} mm, got {start}, {end}")
        if not every > 0:
            raise ValueError(f"every must be > 0 mm, got {every}")
        n = max(int(np.ceil((end - start) / every)), 1) + 1
        s = np.linspace(start, end, n)
        _, normal, _ = centerline.frames(up)
        ups = np.stack([np.interp(s, centerline.arc, normal[:, a]) for a in range(3)], axis=1)
        pts = centerline.at(s)
        ahead = centerline.at(np.minimum(s + look_ahead, centerline.length))
        tan = centerline.tangent_at(s)
        dirs = np.where(np.linalg.norm(ahead - pts, axis=1, keepdims=True) > 1e-6, ahead - pts, tan)
        keys = [Keyframe(tuple(p), tuple(d), tuple(u)) for p, d, u in zip(pts, dirs, ups, strict=True)]
        return cls(keys, speed=speed)

    # -- JSON ---------------------------------------------------------------
    def to_dict(self) -> dict:
        """JSON-ready dict: ``{"speed": mm/s, "keyframes": [{"position", "direction", "up"}, ...]}``."""
        return {"speed": self.speed, "keyframes": [k.to_dict() for k in self.keyframes]}

    @classmethod
    def from_dict(cls, d: dict) -> KeyframePath:
        extra = set(d) - {"speed", "keyframes"}
        if extra:
            raise ValueError(f"unknown keyframe path fields {sorted(extra)}; valid: ['keyframes', 'speed']")
        if "keyframes" not in d:
            raise ValueError("a keyframe path needs 'keyframes'")
        return cls([Keyframe(**k) for k in d["keyframes"]], speed=d.get("speed", 20.0))

    def to_json(self, **kw) -> str:
        return json.dumps(self.to_dict(), **kw)

    @classmethod
    def from_json(cls, text: str) -> KeyframePath:
        return cls.from_dict(json.loads(text))

    def save(self, path) -> None:
        """Write the path as JSON to ``path``."""
        from pathlib import Path

        Path(path).write_text(self.to_json(indent=1))

    @classmethod
    def load(cls, path) -> KeyframePath:
        """Read a path written by :meth:`save`; a bad file raises ValueError naming it."""
        from pathlib import Path

        try:
            return cls.from_json(Path(path).read_text())
        except (OSError, json.JSONDecodeError, TypeError, ValueError) as exc:
            raise ValueError(f"{path}: not a keyframe path: {exc}") from None
