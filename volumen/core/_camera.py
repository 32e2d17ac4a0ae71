"""The camera: a right-handed look-at pinhole or parallel projection in world RAS+ mm.

Conventions (docs/design.md section 2):

* ``position`` is the eye, ``target`` the point looked at, ``up`` a hint for the
  picture's vertical (made orthogonal to the view direction);
* the camera frame is ``forward = normalize(target - position)``,
  ``right = normalize(forward x up)``, ``true_up = right x forward``; image
  column index grows along ``right``, image row index grows along ``-true_up``
  (row 0 is the TOP of the picture);
* ``fov`` is the vertical field of view in degrees (perspective);
  ``parallel_scale`` is half the view height in mm (orthographic).

The anatomical views put the eye on the named side of the patient: the
anterior view looks from +y (anterior) toward -y with superior up, so the
patient's right is on the image's LEFT, as when facing the patient.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Literal, get_args

import numpy as np

from ._jsondata import JsonData
from ._subject import subject_corners

__all__ = ["Camera", "Projection", "View", "VIEWS", "Fit", "FITS", "SUBJECT_FILL", "default_view", "default_camera"]

Projection = Literal["perspective", "orthographic"]
#: what :meth:`Camera.orbit` frames: the volume's bounding sphere, or its subject's box seen from the eye
Fit = Literal["volume", "subject"]
FITS: tuple[str, ...] = get_args(Fit)
#: the share of the picture's height the subject's box spans in the camera fitted to it
SUBJECT_FILL = 0.9
View = Literal["anterior", "posterior", "left", "right", "superior", "inferior"]
VIEWS: tuple[str, ...] = get_args(View)

# view -> (unit vector from the target to the eye, up), world RAS+
_VIEW_DIRS = {
    "anterior": ((0.0, 1.0, 0.0), (0.0, 0.0, 1.0)),
    "posterior": ((0.0, -1.0, 0.0), (0.0, 0.0, 1.0)),
    "left": ((-1.0, 0.0, 0.0), (0.0, 0.0, 1.0)),
    "right": ((1.0, 0.0, 0.0), (0.0, 0.0, 1.0)),
    "superior": ((0.0, 0.0, 1.0), (0.0, 1.0, 0.0)),
    "inferior": ((0.0, 0.0, -1.0), (0.0, 1.0, 0.0)),
}


#: the view facing a slab, by the world axis its normal is nearest: radiology's display of an axial image (seen from
#: the feet, anterior up), a coronal one (from the front) and a sagittal one (from the left)
_FACING = ("left", "anterior", "inferior")


def default_view(volume) -> View:
    """The anatomical view a volume opens with: ``"anterior"``, unless it is a slab (a single slice, a few frames:
    :attr:`Volume.thin_axis`), whose side shows a sliver or a line: then the view facing it (:data:`_FACING`)."""
    thin = volume.thin_axis
    if thin is None:
        return "anterior"
    normal = np.asarray(volume.direction, dtype=float)[:, 2 - thin]  # the thin axis's voxel direction, world
    return _FACING[int(np.argmax(np.abs(normal)))]


def _vec3(name: str, v) -> tuple[float, float, float]:
    a = np.asarray(v, dtype=float).ravel()
    if a.shape != (3,) or not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be three finite numbers (x, y, z) in mm, got {v!r}")
    return (float(a[0]), float(a[1]), float(a[2]))


def _check_choice(name: str, value, choices) -> None:
    if value not in choices:
        raise ValueError(f"{name} must be one of {', '.join(map(repr, choices))}; got {value!r}")


def _rotate(v: np.ndarray, axis: np.ndarray, degrees: float) -> np.ndarray:
    """Rotate ``v`` about the unit ``axis`` by ``degrees`` (right-hand rule, Rodrigues)."""
    a = np.radians(degrees)
    return v * np.cos(a) + np.cross(axis, v) * np.sin(a) + axis * np.dot(axis, v) * (1 - np.cos(a))


@dataclass(frozen=True, kw_only=True)
class Camera(JsonData):
    """A look-at camera in world RAS+ millimetres.

    Parameters
    ----------
    position : (3,) float, mm
        The eye (for orthographic: a point on the image plane; depth is measured from it).
    target : (3,) float, mm
        The point the camera looks at (centre of the picture).
    up : (3,) float
        Direction that appears upward in the picture; need not be orthogonal
        to the view direction, must not be parallel to it.
    fov : float, degrees
        Vertical field of view of the perspective projection, in (0, 180).
    projection : {"perspective", "orthographic"}
    parallel_scale : float, mm
        Half the view height of the orthographic projection.
    near, far : float or None, mm
        Optional distances along the view ray from the eye: nothing nearer
        than ``near`` or farther than ``far`` is drawn. None = unlimited
        (near then defaults to 0, the eye itself).
    """

    position: tuple[float, float, float]
    target: tuple[float, float, float] = (0.0, 0.0, 0.0)
    up: tuple[float, float, float] = (0.0, 0.0, 1.0)
    fov: float = 30.0
    projection: Projection = "perspective"
    parallel_scale: float = 100.0
    near: float | None = None
    far: float | None = None

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "position", _vec3("position", self.position))
        set_(self, "target", _vec3("target", self.target))
        set_(self, "up", _vec3("up", self.up))
        _check_choice("projection", self.projection, get_args(Projection))
        if not 0.0 < float(self.fov) < 180.0:
            raise ValueError(f"fov must be in (0, 180) degrees, got {self.fov}")
        set_(self, "fov", float(self.fov))
        if not float(self.parallel_scale) > 0:
            raise ValueError(f"parallel_scale must be > 0 mm, got {self.parallel_scale}")
        set_(self, "parallel_scale", float(self.parallel_scale))
        for name in ("near", "far"):
            v = getattr(self, name)
            if v is not None:
                if not np.isfinite(v) or v < 0:
                    raise ValueError(f"{name} must be None or a distance >= 0 mm, got {v}")
                set_(self, name, float(v))
        if self.near is not None and self.far is not None and self.far <= self.near:
            raise ValueError(f"far ({self.far}) must be greater than near ({self.near})")
        d = np.subtract(self.target, self.position)
        if np.linalg.norm(d) < 1e-9:
            raise ValueError("position and target coincide: the view direction is undefined")
        if np.linalg.norm(np.cross(d / np.linalg.norm(d), self.up)) < 1e-6:
            raise ValueError("up is parallel to the view direction (target - position)")

    # -- frame --------------------------------------------------------------
    def basis(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Unit vectors ``(right, true_up, forward)``, each (3,) world RAS+.

        Image columns grow along ``right``, rows along ``-true_up``.
        """
        f = _unit([t - p for t, p in zip(self.target, self.position, strict=True)])
        r = _unit(_cross(f, self.up))
        return np.array(r), np.array(_cross(r, f)), np.array(f)

    @property
    def distance(self) -> float:
        """Distance from the eye to the target, mm."""
        return float(np.linalg.norm(np.subtract(self.target, self.position)))

    def pixel_size(self, size: tuple[int, int]) -> float:
        """Size in mm of one pixel at the target distance for an image of ``size = (width, height)``."""
        _, h = size
        half = self.parallel_scale if self.projection == "orthographic" else \
            self.distance * np.tan(np.radians(self.fov) / 2)
        return float(2 * half / h)

    def project(self, xyz, size: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
        """World points to image coordinates.

        Parameters
        ----------
        xyz : (..., 3) float, world RAS+ mm
        size : (width, height) in pixels

        Returns
        -------
        colrow : (..., 2) float
            ``(column, row)`` in pixels, continuous: pixel ``(c, r)`` covers
            ``[c, c+1) x [r, r+1)``, row 0 at the top.
        depth : (...,) float, mm
            Distance along the view ray from the eye (perspective) or from the
            image plane through ``position`` (orthographic): the same quantity
            a renderer writes into ``Image.depth``.
        """
        w, h = size
        p = np.asarray(xyz, dtype=float) - np.asarray(self.position)
        r, u, f = self.basis()
        x, y, z = p @ r, p @ u, p @ f
        if self.projection == "orthographic":
            half = self.parallel_scale
            sx, sy, depth = x / half, y / half, z
        else:
            half = np.tan(np.radians(self.fov) / 2)
            with np.errstate(divide="ignore", invalid="ignore"):
                sx, sy = x / (z * half), y / (z * half)
            depth = np.sqrt(x * x + y * y + z * z)
        col = w / 2 + sx * h / 2
        row = h / 2 - sy * h / 2
        return np.stack([col, row], axis=-1), depth

    def pixel_ray(self, size: tuple[int, int], col, row) -> tuple[np.ndarray, np.ndarray]:
        """The rays through image points, :meth:`project` backwards: ``(origin, unit direction)``, (..., 3) world mm
        each, for continuous ``(col, row)`` (scalars or arrays; pixel ``(c, r)`` covers ``[c, c+1) x [r, r+1)``,
        its centre at ``c + 0.5, r + 0.5``) of a picture of ``size = (width, height)``: from the eye (perspective)
        or from the image plane's point (orthographic)."""
        w, h = size
        right, up, forward = self.basis()
        sx = (np.asarray(col, float) - w / 2) * 2.0 / h
        sy = (h / 2 - np.asarray(row, float)) * 2.0 / h
        plane = sx[..., None] * right + sy[..., None] * up
        eye = np.asarray(self.position, float)
        if self.projection == "orthographic":
            return eye + plane * self.parallel_scale, np.broadcast_to(forward, plane.shape)
        d = forward + np.tan(np.radians(self.fov) / 2) * plane
        return np.broadcast_to(eye, d.shape), d / np.linalg.norm(d, axis=-1, keepdims=True)

    # -- framing a volume ---------------------------------------------------
    @classmethod
    def anatomical(cls, volume, view: View | None = None, *, projection: Projection = "perspective",
                   fov: float = 30.0, zoom: float = 1.0, fit: Fit = "volume") -> Camera:
        """The camera of one of the six anatomical views, framing the volume (or its subject: ``fit``).

        Parameters
        ----------
        volume : Volume
            Framed by its voxel-centre bounding sphere (world RAS+), or by its subject's box (``fit``).
        view : {"anterior", "posterior", "left", "right", "superior", "inferior"} or None
            The side of the patient the eye is on (None: :func:`default_view`, anterior unless the volume is a
            slab such as a single slice). Lateral, anterior and
            posterior views have superior (+z) up; superior and inferior views
            have anterior (+y) up.
        projection, fov :
            As in :class:`Camera`.
        zoom : float
            > 1 magnifies (the eye moves closer, or the parallel scale shrinks).
        fit : {"volume", "subject"}
            As in :meth:`orbit`.
        """
        return cls.orbit(volume, view=view, projection=projection, fov=fov, zoom=zoom, fit=fit)

    @classmethod
    def orbit(cls, volume, *, azimuth: float = 0.0, elevation: float = 0.0, zoom: float = 1.0,
              view: View | None = None, projection: Projection = "perspective",
              fov: float = 30.0, fit: Fit = "volume") -> Camera:
        """A camera on a sphere around the volume's centre, starting from an anatomical view.

        The eye starts on the ``view`` side (see :meth:`anatomical`; None: :func:`default_view`); then
        ``azimuth`` (degrees) rotates it about the view's up axis through the
        centre, counter-clockwise seen from above (right-hand rule: from the
        anterior view, azimuth 90 puts the eye on the patient's left, -90 on
        the right); then ``elevation`` (degrees) rotates it about the camera's
        right axis toward the up side (from anterior, elevation 90 looks down
        from superior). ``up`` turns with the eye.

        ``fit="volume"``: the distance is chosen so the volume's bounding sphere (of its voxel
        centres) fits in the vertical field of view; for orthographic
        projection ``parallel_scale`` is the sphere's radius. ``fit="subject"``: the camera looks at the
        centre of the subject's box (``core.subject_corners``: what the default transfer function shows, not
        the air or background around it) from as far as makes that box, seen from the eye, span
        :data:`SUBJECT_FILL` of the picture's height (and as much of a square picture's width); the parallel
        scale is its half-extent over :data:`SUBJECT_FILL`. Both are divided by ``zoom``.
        """
        view = default_view(volume) if view is None else view
        _check_choice("view", view, VIEWS)
        _check_choice("projection", projection, get_args(Projection))
        _check_choice("fit", fit, FITS)
        if not zoom > 0:
            raise ValueError(f"zoom must be > 0, got {zoom}")
        back, up = _orbit_axes(view, azimuth, elevation)
        floor = min(volume.spacing)
        radius = max(volume.diagonal / 2, floor)
        if fit == "subject":
            centre, dist, scale = _fit_subject(subject_corners(volume), back, up, fov, floor)
        else:
            centre, dist, scale = np.asarray(volume.center, dtype=float), radius / np.sin(np.radians(fov) / 2), radius
        dist = dist / zoom if projection == "perspective" else 2.0 * radius + 10.0 * floor
        return cls(position=tuple(centre + back * dist), target=tuple(centre), up=tuple(up), fov=fov,
                   projection=projection, parallel_scale=scale / zoom)

    def with_(self, **changes) -> Camera:
        """A copy with some fields changed (validated again)."""
        return replace(self, **changes)


def _orbit_axes(view: str, azimuth: float, elevation: float) -> tuple[np.ndarray, np.ndarray]:
    """``(back, up)``: the unit vector from the target to the eye and the picture's up, of ``view`` turned by
    ``azimuth`` about its up axis, then by ``elevation`` about the camera's right axis (:meth:`Camera.orbit`)."""
    back, up = (np.array(v) for v in _VIEW_DIRS[view])
    back = _rotate(back, up, azimuth)
    right = np.cross(-back, up)
    right /= np.linalg.norm(right)
    return _rotate(back, right, -elevation), _rotate(up, right, -elevation)


def _fit_subject(corners: np.ndarray, back: np.ndarray, up: np.ndarray, fov: float,
                 floor: float) -> tuple[np.ndarray, float, float]:
    """``(target, distance, parallel scale)`` fitting the box of ``corners`` ((8, 3) world mm) seen along
    ``-back`` with ``up`` up: each corner within :data:`SUBJECT_FILL` of the half field of view across and up,
    at its own depth (the near face looks larger), half-extents at least ``floor`` mm."""
    centre = corners.mean(axis=0)
    rel = corners - centre
    right = np.cross(-back, up)
    right /= np.linalg.norm(right)
    across = np.maximum(np.abs(rel @ right), np.abs(rel @ up))
    half = max(float(across.max()), floor)
    slope = np.tan(np.radians(fov) / 2) * SUBJECT_FILL
    dist = max(float(np.max(across / slope + rel @ back)), half / slope)
    return centre, dist, half / SUBJECT_FILL


def default_camera(volume, *, view: View | None = None, azimuth: float = 0.0, elevation: float = 0.0,
                   zoom: float = 1.0, projection: Projection = "perspective") -> Camera:
    """The camera a volume is first shown with where none is named: :meth:`Camera.orbit` fitted to the subject
    (``fit="subject"``), the one answer of ``render_volume``, the command line, the app, the notebook and the
    browser page."""
    return Camera.orbit(volume, view=view, azimuth=azimuth, elevation=elevation, zoom=zoom, projection=projection,
                        fit="subject")


def _cross(a, b) -> tuple[float, float, float]:
    """``a x b`` of two 3-vectors (plain floats: a frame's basis costs microseconds, ``np.cross`` ten times more)."""
    return a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]


def _unit(v) -> tuple[float, float, float]:
    n = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    return v[0] / n, v[1] / n, v[2] / n
