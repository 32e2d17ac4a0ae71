"""Virtual endoscopy in the application, without Qt: path, flight with collisions, playback.

Built on :mod:`volumen.endoscopy`, the same calls as ``volumen fly``. The user
picks a start and an end point in the slice views; :meth:`Endoscopy.compute`
finds the lumen from the start (its polarity, range and wall threshold estimated
from the data, grown with explosion control, tagged fluid joined, thin bridges
cut: :func:`~volumen.endoscopy.lumen_wall`), or reads it from a segmentation file
(:attr:`Endoscopy.mask_file`), and finds its centerline
(:func:`~volumen.endoscopy.checked_centerline`); a lumen that leaks is refused
with the same one-line :class:`~volumen.errors.LumenError` as the command line.
The lumen is kept (:attr:`Endoscopy.mask`) for the slice views' overlay, the wall
drawn and collided with is the lumen's (:meth:`Endoscopy.drawn_volume`), and
:meth:`Endoscopy.cpr` draws the curved planar reformation along the path.
Flight is manual (a :class:`ManualNavigator` whose moves
go through a :class:`Collider`, so the eye stays ``margin`` mm inside the
lumen; :attr:`Endoscopy.blocked` tells when the last move hit the wall),
guided (a :class:`GuidedNavigator` advancing along the centerline), or the
automatic keyframe path played forward or backward.
"""

from __future__ import annotations

import numpy as np

__all__ = ["Endoscopy", "LUMENS"]

#: the lumen kinds offered (``auto``: air or contrast, decided from the data at the start point); the same as
#: ``volumen.endoscopy.LUMEN_KINDS`` (a test checks), not imported here to keep Numba out of the app's start
LUMENS = ("auto", "air", "contrast")


class Endoscopy:
    """Endoscopy state of one volume.

    Parameters
    ----------
    volume : Volume
    lumen : {"auto", "air", "contrast"}
    margin : float, mm
        Closest the eye may come to the wall.
    fov : float, degrees
        Field of view of the endoscopic camera.
    """

    def __init__(self, volume, *, lumen: str = "auto", margin: float = 2.0, fov: float = 90.0):
        if lumen not in LUMENS:
            raise ValueError(f"lumen must be one of {', '.join(LUMENS)}, got {lumen!r}")
        self.volume = volume
        self.lumen = lumen
        self.margin = float(margin)
        self.fov = float(fov)
        self.start: np.ndarray | None = None
        self.end: np.ndarray | None = None
        self.centerline = None
        self.mask_file = None
        self.label = None
        self.mask = None
        self.estimate = None
        self.wall = None
        self.profile = None
        self._drawn = None
        self.navigator = None
        self.guided = None
        self.blocked = False
        self._collider = None

    # -- path -----------------------------------------------------------------
    def compute(self):
        """Find the lumen holding :attr:`start` (and :attr:`end`) and the centerline between them (world mm).

        Sets :attr:`mask`, :attr:`estimate`, :attr:`wall` and :attr:`profile` (the lumen's cross-sections along
        the centerline, :func:`volumen.analysis.measure`); returns the centerline. Raises ValueError (a
        :class:`~volumen.errors.LumenError` naming the point or the leak) when a point is missing, outside
        the scan, in no lumen, the two are not connected, or the lumen leaks.
        """
        from ..analysis import measure
        from ..endoscopy import check_points_in_mask, checked_centerline, load_lumen_mask, lumen_wall, smooth_wall

        if self.start is None or self.end is None:
            raise ValueError("pick a start and an end point in the slice views first")
        mask = None
        if self.mask_file:
            mask = load_lumen_mask(self.mask_file, self.volume, self.label)
            check_points_in_mask(self.volume, mask, {"start": self.start, "end": self.end}, self.mask_file)
        wall = lumen_wall(self.volume, self.start, self.end, kind=self.lumen, mask=mask)
        self.centerline = checked_centerline(self.volume, wall.mask, self.start, self.end)
        if mask is None:  # a grown lumen whose values vary more than its threshold allows: its smoothed boundary
            wall = smooth_wall(self.volume, wall, self.centerline)
        self.mask, self.estimate, self.wall, self._drawn, self._collider = wall.mask, wall.estimate, wall, None, None
        self.profile = measure(self.volume, wall.mask, self.centerline, refine=mask is None)
        return self.centerline

    def lumen_estimate(self):
        """The lumen's :class:`~volumen.endoscopy.LumenEstimate` (from the start point when not computed yet)."""
        if self.estimate is None:
            from ..endoscopy import estimate_lumen, lumen_voxel

            if self.start is None:
                raise ValueError("pick a start point first")
            self.estimate = estimate_lumen(self.volume, lumen_voxel(self.volume, self.start), self.lumen)
        return self.estimate

    def drawn_volume(self):
        """The volume the flight draws and collides with: the lumen's wall (:meth:`LumenWall.volume`) once
        computed, else the scan."""
        if self.wall is None:
            return self.volume
        if self._drawn is None:
            self._drawn = self.wall.volume(self.volume)
        return self._drawn

    def transfer(self):
        """The endoscopy transfer function made from the lumen's values."""
        return self.lumen_estimate().transfer()

    @property
    def collider(self):
        """The :class:`~volumen.endoscopy.Collider` of the lumen's wall (built on first use)."""
        if self._collider is None:
            from ..endoscopy import Collider

            self._collider = Collider(self.lumen_estimate().wall_field(self.drawn_volume()), margin=self.margin)
        return self._collider

    def cpr(self, kind: str = "straightened", width: float | None = None, sections: int = 4):
        """``(H, W, 3)`` uint8 picture of the curved planar reformation along the centerline (``width`` mm across,
        None: ``endoscopy.cpr_width``), ``sections`` cross-sections evenly spread, marked and shown beside it."""
        from ..endoscopy import cpr_figure, cpr_width, curved_reformation

        if self.centerline is None:
            raise ValueError("compute the centerline first")
        cl = self.centerline
        width = cpr_width(cl) if width is None else width
        marks = list(np.linspace(0.0, cl.length, sections + 2)[1:-1])
        return cpr_figure(self.volume, cl, curved_reformation(self.volume, cl, kind=kind, width=width), marks,
                          section_width=width)

    def path(self, speed: float = 20.0):
        """The automatic :class:`~volumen.endoscopy.KeyframePath` along the centerline."""
        from ..endoscopy import KeyframePath, aim_keyframes

        if self.centerline is None:
            raise ValueError("compute the centerline first")
        every = max(self.centerline.length / 12.0, 2.0)
        path = KeyframePath.from_centerline(self.centerline, every=every, look_ahead=every, speed=speed)
        return path if self.mask is None else aim_keyframes(path, self.centerline, self.volume, self.mask)

    # -- flight ---------------------------------------------------------------
    def start_manual(self, pose=None, speed: float = 10.0):
        """Start manual flight at ``pose`` (default: the path's start, looking along it)."""
        from ..endoscopy import ManualNavigator

        if pose is None:
            pose = self._start_pose()
        self.navigator = ManualNavigator(pose, self.collider, speed=speed)
        self.guided = None
        self.blocked = False
        return self.navigator

    def start_guided(self, speed: float = 10.0):
        """Start guided flight along the centerline."""
        from ..endoscopy import GuidedNavigator

        if self.centerline is None:
            raise ValueError("compute the centerline first")
        self.guided = GuidedNavigator(self.centerline, self.collider, speed=speed)
        self.navigator = None
        self.blocked = False
        return self.guided

    def stop(self) -> None:
        self.navigator = self.guided = None
        self.blocked = False

    @property
    def flying(self) -> bool:
        return self.navigator is not None or self.guided is not None

    def _start_pose(self):
        from ..endoscopy import Pose

        if self.centerline is not None:
            p = self.centerline.at(0.0)
            t = self.centerline.tangent_at(min(2.0, self.centerline.length))
        elif self.start is not None:
            p = np.asarray(self.start, float)
            t = (np.asarray(self.end, float) - p) if self.end is not None else np.array([0.0, 0.0, -1.0])
        else:
            raise ValueError("pick a start point first")
        up = (0.0, 0.0, 1.0) if abs(t[2]) < 0.9 * np.linalg.norm(t) else (0.0, 1.0, 0.0)
        return Pose(tuple(p), tuple(t), up)

    @property
    def pose(self):
        if self.guided is not None:
            return self.guided.pose
        return None if self.navigator is None else self.navigator.pose

    def move(self, right: float = 0.0, up: float = 0.0, forward: float = 0.0) -> bool:
        """A manual move (mm along the camera's axes); True when the wall blocked it (:attr:`blocked`)."""
        nav = self.navigator if self.navigator is not None else (
            self.guided.leave_path() if self.guided is not None else None)
        if nav is None:
            raise ValueError("not flying: start manual or guided flight first")
        res = nav.move(right=right, up=up, forward=forward)
        self.blocked = bool(res is not None and res.blocked)
        return self.blocked

    def turn(self, yaw: float = 0.0, pitch: float = 0.0) -> None:
        """Turn the view (degrees): left for positive yaw, up for positive pitch."""
        if self.guided is not None:
            self.guided.steer(yaw, pitch)
        elif self.navigator is not None:
            self.navigator.yaw(yaw)
            self.navigator.pitch(pitch)

    def camera(self):
        """The endoscopic camera of the current pose (None when not flying)."""
        pose = self.pose
        return None if pose is None else pose.camera(fov=self.fov, near=0.5 * self.margin)

    # -- JSON -----------------------------------------------------------------
    def to_dict(self) -> dict:
        return {"lumen": self.lumen, "margin": self.margin, "fov": self.fov,
                "mask_file": None if self.mask_file is None else str(self.mask_file), "label": self.label,
                "start": None if self.start is None else [float(v) for v in self.start],
                "end": None if self.end is None else [float(v) for v in self.end],
                "centerline": None if self.centerline is None else self.centerline.to_dict()}

    @classmethod
    def from_dict(cls, volume, d: dict) -> Endoscopy:
        from ..endoscopy import Centerline

        e = cls(volume, lumen=d.get("lumen", "auto"), margin=d.get("margin", 2.0), fov=d.get("fov", 90.0))
        e.mask_file, e.label = d.get("mask_file"), d.get("label")
        e.start = None if d.get("start") is None else np.asarray(d["start"], float)
        e.end = None if d.get("end") is None else np.asarray(d["end"], float)
        if d.get("centerline"):
            e.centerline = Centerline.from_dict(d["centerline"])
        return e
