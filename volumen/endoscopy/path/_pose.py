"""The endoscope's pose (eye, view direction, up) and unit quaternions to turn and blend orientations.

A pose's orientation is the right-handed frame of :class:`volumen.core.Camera`
(``right = forward x up``, ``true_up = right x forward``). As a rotation
matrix its columns are ``(right, true_up, -forward)`` (camera looks down its
-z, as in OpenGL), stored as a unit quaternion ``(w, x, y, z)``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Pose", "quat_from_matrix", "quat_to_matrix", "quat_from_axis_angle", "quat_mul", "slerp"]


def _unit(v, name: str) -> np.ndarray:
    a = np.asarray(v, dtype=float).reshape(3)
    n = np.linalg.norm(a)
    if not (np.isfinite(n) and n > 1e-12):
        raise ValueError(f"{name} must be a finite non-zero vector (x, y, z), got {v!r}")
    return a / n


def quat_from_matrix(m: np.ndarray) -> np.ndarray:
    """Unit quaternion ``(w, x, y, z)`` (w >= 0) of a 3x3 rotation matrix (Shepperd's method)."""
    m = np.asarray(m, float)
    tr = m[0, 0] + m[1, 1] + m[2, 2]
    if tr > 0:
        s = 2.0 * np.sqrt(tr + 1.0)
        q = [0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s]
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = 2.0 * np.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
        q = [(m[2, 1] - m[1, 2]) / s, 0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s]
    elif m[1, 1] > m[2, 2]:
        s = 2.0 * np.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2])
        q = [(m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s]
    else:
        s = 2.0 * np.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1])
        q = [(m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s]
    q = np.array(q)
    q /= np.linalg.norm(q)
    return -q if q[0] < 0 else q


def quat_to_matrix(q) -> np.ndarray:
    """3x3 rotation matrix of a quaternion ``(w, x, y, z)`` (normalized first)."""
    w, x, y, z = np.asarray(q, float) / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def quat_from_axis_angle(axis, degrees: float) -> np.ndarray:
    """Quaternion of a rotation by ``degrees`` about ``axis`` (right-hand rule)."""
    a = _unit(axis, "axis")
    h = np.radians(degrees) / 2
    return np.concatenate([[np.cos(h)], np.sin(h) * a])


def quat_mul(a, b) -> np.ndarray:
    """Hamilton product ``a * b`` (apply ``b`` first, then ``a``)."""
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return np.array([w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                     w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2])


def slerp(q0, q1, u: float) -> np.ndarray:
    """Spherical linear interpolation from ``q0`` (u = 0) to ``q1`` (u = 1) along the shorter arc."""
    q0 = np.asarray(q0, float)
    q1 = np.asarray(q1, float)
    c = float(np.dot(q0, q1))
    if c < 0:
        q1, c = -q1, -c
    if c > 0.9995:  # nearly equal: normalized lerp (no division by a tiny sine)
        q = q0 + u * (q1 - q0)
        return q / np.linalg.norm(q)
    th = np.arccos(min(c, 1.0))
    s = np.sin(th)
    return (np.sin((1 - u) * th) * q0 + np.sin(u * th) * q1) / s


@dataclass(frozen=True)
class Pose:
    """Where the endoscope is and where it looks, world RAS+.

    Parameters
    ----------
    position : (3,) float, mm
    forward : (3,) float
        View direction (normalized on construction).
    up : (3,) float
        Picture's up; made orthogonal to ``forward`` and normalized.
    """

    position: tuple[float, float, float]
    forward: tuple[float, float, float]
    up: tuple[float, float, float] = (0.0, 0.0, 1.0)

    def __post_init__(self):
        p = np.asarray(self.position, float).reshape(3)
        if not np.all(np.isfinite(p)):
            raise ValueError(f"position must be finite (x, y, z) mm, got {self.position!r}")
        f = _unit(self.forward, "forward")
        u = np.asarray(self.up, float).reshape(3)
        u = u - np.dot(u, f) * f
        if np.linalg.norm(u) < 1e-9:
            raise ValueError("up is parallel to forward")
        u = u / np.linalg.norm(u)
        object.__setattr__(self, "position", tuple(float(v) for v in p))
        object.__setattr__(self, "forward", tuple(float(v) for v in f))
        object.__setattr__(self, "up", tuple(float(v) for v in u))

    @property
    def right(self) -> np.ndarray:
        """(3,) unit vector ``forward x up``."""
        return np.cross(self.forward, self.up)

    def matrix(self) -> np.ndarray:
        """3x3 rotation with columns ``(right, up, -forward)``."""
        return np.stack([self.right, np.asarray(self.up), -np.asarray(self.forward)], axis=1)

    def quaternion(self) -> np.ndarray:
        """Orientation as a unit quaternion ``(w, x, y, z)``."""
        return quat_from_matrix(self.matrix())

    @classmethod
    def from_quaternion(cls, position, q) -> Pose:
        """The pose at ``position`` (mm) with the orientation of quaternion ``q``."""
        m = quat_to_matrix(q)
        return cls(position=tuple(position), forward=tuple(-m[:, 2]), up=tuple(m[:, 1]))

    def rotated(self, axis, degrees: float) -> Pose:
        """The pose turned by ``degrees`` about a world ``axis`` through the eye."""
        r = quat_to_matrix(quat_from_axis_angle(axis, degrees))
        return Pose(self.position, tuple(r @ np.asarray(self.forward)), tuple(r @ np.asarray(self.up)))

    def camera(self, *, fov: float = 90.0, near: float = 0.5, far: float | None = None):
        """An endoscopic perspective :class:`~volumen.core.Camera` at this pose.

        Parameters
        ----------
        fov : float, degrees
            Vertical field of view, 30..140 for endoscopy.
        near : float, mm
            Near plane just ahead of the eye (keep it below the collision margin).
        far : float or None, mm
        """
        from ...core import Camera

        if not 1.0 <= fov <= 170.0:
            raise ValueError(f"fov must be within [1, 170] degrees (endoscopes: 30..140), got {fov}")
        p = np.asarray(self.position)
        return Camera(position=tuple(p), target=tuple(p + np.asarray(self.forward) * 10.0), up=self.up, fov=fov,
                      near=near, far=far)

    def to_dict(self) -> dict:
        return {"position": list(self.position), "forward": list(self.forward), "up": list(self.up)}

    @classmethod
    def from_dict(cls, d: dict) -> Pose:
        extra = set(d) - {"position", "forward", "up"}
        if extra:
            raise ValueError(f"unknown Pose fields {sorted(extra)}; valid: ['forward', 'position', 'up']")
        return cls(**{k: tuple(v) for k, v in d.items()})
