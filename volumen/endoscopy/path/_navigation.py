"""Interactive navigation without a GUI: manual flight and guided flight along a path.

Plain classes holding a :class:`Pose`; a front end (the desktop application,
a script) calls their methods from its input events and reads ``pose`` (or
``camera()``) each frame. Motions go through a :class:`Collider` when one is
given, so the eye never comes closer to the wall than its margin.

* :class:`ManualNavigator`: move forward/back, strafe right/left, up/down at
  ``speed`` mm/s for ``dt`` seconds; yaw, pitch and roll in degrees about the
  camera's own axes.
* :class:`GuidedNavigator`: the eye advances along a :class:`Centerline` at
  ``speed`` mm/s while the user steers the view (yaw/pitch offsets from the
  path's direction); :meth:`~GuidedNavigator.leave_path` hands control to
  manual moves; :meth:`~GuidedNavigator.snap_back` returns to the nearest path point.
"""

from __future__ import annotations

import numpy as np

from ._pose import Pose

__all__ = ["ManualNavigator", "GuidedNavigator"]


class ManualNavigator:
    """Free flight with collisions.

    Parameters
    ----------
    pose : Pose
        Start pose.
    collider : Collider or None
        Checks every move; None flies through walls.
    speed : float, mm/s
    """

    def __init__(self, pose: Pose, collider=None, *, speed: float = 10.0):
        if not isinstance(pose, Pose):
            raise ValueError(f"pose must be a Pose, got {type(pose).__name__}")
        if not (np.isfinite(speed) and speed > 0):
            raise ValueError(f"speed must be > 0 mm/s, got {speed}")
        self.pose = pose
        self.collider = collider
        self.speed = float(speed)
        self.last_move = None

    def camera(self, **kw):
        """The pose's endoscopic camera (see :meth:`Pose.camera`)."""
        return self.pose.camera(**kw)

    # -- translation ----------------------------------------------------------
    def move(self, right: float = 0.0, up: float = 0.0, forward: float = 0.0):
        """Move by a motion given in the camera's frame (mm along right, up, forward).

        Returns the collider's :class:`MoveResult` (None without a collider).
        """
        p = self.pose
        m = right * p.right + up * np.asarray(p.up) + forward * np.asarray(p.forward)
        if self.collider is None:
            self.pose = Pose(tuple(np.asarray(p.position) + m), p.forward, p.up)
            self.last_move = None
            return None
        res = self.collider.move(p.position, m)
        self.pose = Pose(tuple(res.position), p.forward, p.up)
        self.last_move = res
        return res

    def forward(self, dt: float):
        """Fly ahead for ``dt`` seconds at ``speed`` (negative ``dt``: back)."""
        return self.move(forward=self.speed * dt)

    def back(self, dt: float):
        """Fly backward for ``dt`` seconds."""
        return self.move(forward=-self.speed * dt)

    def strafe(self, dt: float, vertical: float = 0.0):
        """Slide sideways for ``dt`` seconds (to the right; negative: left), and ``vertical`` x that upward."""
        return self.move(right=self.speed * dt, up=self.speed * dt * vertical)

    # -- rotation -------------------------------------------------------------
    def yaw(self, degrees: float) -> None:
        """Turn left (positive) or right about the camera's up axis."""
        self.pose = self.pose.rotated(self.pose.up, degrees)

    def pitch(self, degrees: float) -> None:
        """Tilt the view up (positive) or down about the camera's right axis."""
        self.pose = self.pose.rotated(self.pose.right, degrees)

    def roll(self, degrees: float) -> None:
        """Roll the camera about the view direction (positive: its up turns toward its right, clockwise seen
        from behind)."""
        self.pose = self.pose.rotated(self.pose.forward, degrees)

    def look(self, direction, up=None) -> None:
        """Point the view along ``direction`` (world), keeping the current up unless ``up`` is given."""
        self.pose = Pose(self.pose.position, tuple(direction), tuple(self.pose.up if up is None else up))


class GuidedNavigator:
    """Flight along a path with a free view and the option to leave and come back.

    Parameters
    ----------
    centerline : Centerline
    collider : Collider or None
        Used while off the path (manual moves).
    speed : float, mm/s
        Advance along the path (negative: backward).
    arc : float, mm
        Starting arc length.
    """

    def __init__(self, centerline, collider=None, *, speed: float = 10.0, arc: float = 0.0):
        self.centerline = centerline
        self.speed = float(speed)
        self.arc = float(np.clip(arc, 0.0, centerline.length))
        self.yaw_offset = 0.0
        self.pitch_offset = 0.0
        _, normal, _ = centerline.frames()
        self._normal = normal
        self.on_path = True
        self.manual = ManualNavigator(self._path_pose(), collider, speed=abs(self.speed) or 1.0)

    def _path_frame(self, s: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        cl = self.centerline
        t = cl.tangent_at(s) * (1.0 if self.speed >= 0 else -1.0)
        n = np.array([np.interp(s, cl.arc, self._normal[:, a]) for a in range(3)])
        n = n - np.dot(n, t) * t
        return cl.at(s), t, n / np.linalg.norm(n)

    def _path_pose(self) -> Pose:
        p, t, n = self._path_frame(self.arc)
        pose = Pose(tuple(p), tuple(t), tuple(n))
        pose = pose.rotated(pose.up, self.yaw_offset)
        return pose.rotated(pose.right, self.pitch_offset)

    @property
    def pose(self) -> Pose:
        """The current pose (on the path, or where manual moves took it)."""
        return self._path_pose() if self.on_path else self.manual.pose

    def camera(self, **kw):
        return self.pose.camera(**kw)

    @property
    def at_end(self) -> bool:
        """True when the advance has reached the end of the path (or its start, going backward)."""
        return self.arc >= self.centerline.length if self.speed >= 0 else self.arc <= 0.0

    def advance(self, dt: float) -> Pose:
        """Move along the path for ``dt`` seconds (no effect while off the path); returns the pose."""
        if self.on_path:
            self.arc = float(np.clip(self.arc + self.speed * dt, 0.0, self.centerline.length))
        return self.pose

    def steer(self, yaw: float = 0.0, pitch: float = 0.0) -> None:
        """Turn the view relative to the path direction (degrees; offsets accumulate, pitch kept in [-89, 89])."""
        if self.on_path:
            self.yaw_offset = float((self.yaw_offset + yaw + 180.0) % 360.0 - 180.0)
            self.pitch_offset = float(np.clip(self.pitch_offset + pitch, -89.0, 89.0))
        else:
            self.manual.yaw(yaw)
            self.manual.pitch(pitch)

    def leave_path(self) -> ManualNavigator:
        """Switch to manual flight from the current pose; returns the :class:`ManualNavigator` to drive."""
        if self.on_path:
            self.manual.pose = self._path_pose()
            self.on_path = False
        return self.manual

    def snap_back(self) -> Pose:
        """Return to the path point nearest the eye (keeping the view offsets) and resume guided flight."""
        if not self.on_path:
            self.arc, _ = self.centerline.project(self.manual.pose.position)
            self.on_path = True
        return self.pose
