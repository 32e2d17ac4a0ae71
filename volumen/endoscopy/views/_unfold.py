"""The unfolded view ("virtual dissection"): the lumen's wall cut open along the path and laid flat.

For each centerline sample ``i`` (a column, arc length ``s_i``) and each angle
``theta_j`` around it (a row), a ray leaves the centerline point in the plane
normal to the path, along ``cos(theta) N_i - sin(theta) B_i`` with ``(T, N, B)``
the rotation-minimizing frame of :meth:`Centerline.frames` (so an angle means
the same side of the wall all along the path, without twist). Angles run from
N toward ``-B = N x T`` so that the picture is the mucosa seen from INSIDE, as
in the flythrough: looking at the wall with the path running to the right
(+T), the image's up is ``T x e(theta)``, the direction of decreasing rows. The ray stops
at the wall of a :class:`WallField` (first crossing, as for collisions); the
hit is shaded with the Phong terms of ``volumen.render.optics`` lit from the
centerline point, and its distance is kept as a radius map. A polyp shows up
as a bright bump where the radius dips below its neighbours'.

Rows run over angles 0..360 degrees (top to bottom), columns over the arc.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ...jit import njit, run_parts
from ...render.optics import phong_terms
from ..wall._first_hit import NO_HIT, Wall, first_hit, wall_gradient

__all__ = ["Unfolded", "WallLook", "unfold"]


class WallLook(NamedTuple):
    """How the unfolded wall is shaded: Phong terms lit from the centerline point (the kernel gets ``color`` as an
    array of three)."""

    color: tuple[float, float, float] = (0.93, 0.6, 0.52)  #: linear RGB of the wall
    ambient: float = 0.15
    diffuse: float = 0.75
    specular: float = 0.2
    shininess: float = 20.0  #: specular exponent


class _Rays(NamedTuple):
    """The rays of one unfolded view: per column a centerline point and the frame's two vectors, per row an angle."""

    pts: np.ndarray    #: centerline points (N, 3), world mm
    nrm: np.ndarray    #: angle-0 vectors (N, 3)
    bin_: np.ndarray   #: angle-90 vectors (N, 3)
    cos_a: np.ndarray  #: cosine of each row's angle (M,)
    sin_a: np.ndarray  #: sine of each row's angle (M,)
    tmax: float        #: how far a ray looks for the wall, mm


@njit(cache=True, nogil=True)
def _unfold_kernel(part, parts, w, r, look, rgb, radius):
    """Columns (centerline samples) of part ``part`` of ``parts`` (``volumen.jit.run_parts``)."""
    pts, nrm, bin_, cos_a, sin_a = r.pts, r.nrm, r.bin_, r.cos_a, r.sin_a
    color, ka, kd, ks = look.color, look.ambient, look.diffuse, look.specular
    n = pts.shape[0]
    m = cos_a.shape[0]
    for i in range(part * n // parts, (part + 1) * n // parts):
        for j in range(m):
            dx = cos_a[j] * nrm[i, 0] + sin_a[j] * bin_[i, 0]
            dy = cos_a[j] * nrm[i, 1] + sin_a[j] * bin_[i, 1]
            dz = cos_a[j] * nrm[i, 2] + sin_a[j] * bin_[i, 2]
            t = first_hit(w, (pts[i, 0], pts[i, 1], pts[i, 2]), (dx, dy, dz), r.tmax)
            if t >= NO_HIT:
                radius[j, i] = np.inf
                rgb[j, i, 0] = 0.0
                rgb[j, i, 1] = 0.0
                rgb[j, i, 2] = 0.0
                continue
            radius[j, i] = t
            gx, gy, gz = wall_gradient(w, (pts[i, 0] + t * dx, pts[i, 1] + t * dy, pts[i, 2] + t * dz))
            g = np.sqrt(gx * gx + gy * gy + gz * gz)
            diff = 1.0
            spec = 0.0
            if g > 0.0:
                nx, ny, nz = gx / g, gy / g, gz / g
                if nx * dx + ny * dy + nz * dz > 0.0:  # face the centerline (two-sided)
                    nx, ny, nz = -nx, -ny, -nz
                diff, spec = phong_terms((nx, ny, nz), (-dx, -dy, -dz), (-dx, -dy, -dz), look.shininess)
            rgb[j, i, 0] = min(color[0] * (ka + kd * diff) + ks * spec, 1.0)
            rgb[j, i, 1] = min(color[1] * (ka + kd * diff) + ks * spec, 1.0)
            rgb[j, i, 2] = min(color[2] * (ka + kd * diff) + ks * spec, 1.0)


@dataclass(frozen=True, eq=False)
class Unfolded:
    """An unfolded view.

    Attributes
    ----------
    rgb : (M, N, 3) float32
        Linear RGB in [0, 1]; row j = angle ``angle[j]``, column i = arc ``arc[i]``; black where no wall was met.
    radius : (M, N) float32, mm
        Distance from the centerline point to the wall along each ray (inf: none within reach).
    arc : (N,) float, mm
        Arc length of each column along the centerline.
    angle : (M,) float, degrees
        Angle of each row from the frame's normal N toward ``-B = N x T``.
    normal, binormal : (N, 3) float
        The vectors at angle 0 (N) and 90 degrees (``-B``) at each column.
    """

    rgb: np.ndarray
    radius: np.ndarray
    arc: np.ndarray
    angle: np.ndarray
    normal: np.ndarray
    binormal: np.ndarray

    def angle_of(self, arc: float, direction) -> float:
        """Angle (degrees, 0..360) at which a world ``direction`` leaving the centerline at ``arc`` mm appears."""
        n = np.array([np.interp(arc, self.arc, self.normal[:, a]) for a in range(3)])
        b = np.array([np.interp(arc, self.arc, self.binormal[:, a]) for a in range(3)])
        d = np.asarray(direction, float)
        return float(np.degrees(np.arctan2(d @ b, d @ n)) % 360.0)

    def to_uint8(self) -> np.ndarray:
        """(M, N, 3) uint8 picture (linear values times 255, through :meth:`volumen.core.Image.to_uint8`)."""
        from ...core import Image

        m, n, _ = self.rgb.shape
        rgba = np.concatenate([self.rgb, np.ones((m, n, 1), np.float32)], axis=2).astype(np.float32)
        return Image(rgba=rgba, depth=np.where(np.isfinite(self.radius), self.radius, np.inf).astype(np.float32)
                     ).to_uint8()

    def save(self, path) -> None:
        """Write :meth:`to_uint8` as a PNG."""
        from PIL import Image as PILImage

        PILImage.fromarray(self.to_uint8()).save(path)


def unfold(wall, centerline, *, angles: int = 360, step: float | None = None, max_radius: float | None = None,
           look: WallLook | None = None, normal=None) -> Unfolded:
    """Unfold the wall around a centerline into an (angles x samples) picture.

    Parameters
    ----------
    wall : WallField
        What counts as the wall (e.g. ``WallField.from_threshold(volume, -500)``).
    centerline : Centerline
    angles : int
        Rows: rays around each sample, evenly over 360 degrees.
    step : float or None, mm
        Column spacing along the arc; None keeps the centerline's own points.
    max_radius : float or None, mm
        How far a ray looks for the wall (default: 3 x the largest centerline radius, at least 20 mm).
    look : WallLook or None
        The wall's linear RGB colour and Phong coefficients (light at the centerline point).
    normal : (3,) float or None
        First normal of the rotation-minimizing frame (angle 0), see :meth:`Centerline.frames`.

    Returns
    -------
    Unfolded
    """
    from ..path._centerline import Centerline

    if angles < 4:
        raise ValueError(f"angles must be >= 4, got {angles}")
    look = WallLook() if look is None else look
    if len(look.color) != 3:
        raise ValueError(f"look.color must be linear (r, g, b), got {look.color}")
    cl = centerline
    if step is not None:
        if not step > 0:
            raise ValueError(f"step must be > 0 mm, got {step}")
        s = np.linspace(0.0, cl.length, max(int(round(cl.length / step)), 1) + 1)
        cl = Centerline(cl.at(s), cl.radius_at(s), s)
    _, nrm, bin_ = cl.frames(normal)
    bin_ = -bin_  # angle 90 degrees: N x T, so the picture is the wall seen from inside (not mirrored)
    if max_radius is None:
        max_radius = max(3.0 * float(np.max(cl.radius)), 20.0)
    theta = np.radians(np.arange(angles) * 360.0 / angles)
    rgb = np.zeros((angles, len(cl.points), 3), np.float32)
    radius = np.zeros((angles, len(cl.points)), np.float32)
    rays = _Rays(cl.points, np.ascontiguousarray(nrm), np.ascontiguousarray(bin_), np.cos(theta), np.sin(theta),
                 float(max_radius))
    look = WallLook(np.asarray(look.color, np.float64), *(float(v) for v in look[1:]))  # the kernel's record
    run_parts(_unfold_kernel, len(cl.points), Wall(wall.field, wall.geometry, float(wall.level), wall.step), rays, look,
              rgb, radius)
    return Unfolded(rgb, radius, cl.arc.copy(), np.degrees(theta), nrm, bin_)
