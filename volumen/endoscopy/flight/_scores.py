"""How good a flythrough is, against a ground truth: one set of definitions for the tests, benchmarks and reports.

* :func:`dice` -- overlap of a lumen with the true one, ``2 |A & B| / (|A| + |B|)``;
* :func:`keyframes_inside` -- the fraction of a path's keyframes whose eye lies inside
  the true lumen (the trilinear interpolation of the truth mask at least 0.5: on the
  lumen's side of the half-way boundary);
* :func:`look_down_ratio` -- the median depth of a frame's centre (its middle fifth
  each way) over the median depth of its border (the outer tenth); rays that meet
  nothing count as 1 m. A frame *looks down the lumen* when the ratio is at least
  :data:`LOOK_DOWN` (2): the centre sees twice as far as the sides;
* :func:`wall_offsets` -- for every pixel of a frame that meets the wall, the
  first-hit depth less the distance along the same ray to the boundary of a lumen
  mask (where the trilinear interpolation of the mask falls to 0.5), times the cosine
  of the ray's incidence on that boundary (the distance between the two surfaces
  across them: a ray grazing the wall turns a small gap into a long one), in voxels
  (the largest spacing): how far the drawn wall lies from the mask's;
* :func:`score_flight` -- all of them for a flight, as a :class:`FlightScore`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...jit import njit, run_parts
from ..wall._first_hit import first_hit

__all__ = ["FlightScore", "score_flight", "dice", "keyframes_inside", "look_down_ratio", "wall_offsets",
           "LOOK_DOWN", "pixel_rays"]

#: a frame looks down the lumen when its centre's median depth is at least this times its border's
LOOK_DOWN = 2.0
NO_HIT_MM = 1000.0


def dice(a: np.ndarray, b: np.ndarray) -> float:
    """Dice coefficient of two bool masks of the same shape (1 when both are empty)."""
    a, b = np.asarray(a, bool), np.asarray(b, bool)
    total = int(a.sum()) + int(b.sum())
    return 1.0 if total == 0 else 2.0 * float(np.sum(a & b)) / total


def _inside(volume, mask: np.ndarray, points) -> np.ndarray:
    from scipy import ndimage

    zyx = volume.world_to_index(np.atleast_2d(np.asarray(points, float)))[:, ::-1]
    vals = ndimage.map_coordinates(mask.astype(np.float32), zyx.T, order=1, mode="constant", cval=0.0)
    return vals >= 0.5


def keyframes_inside(volume, truth: np.ndarray, path) -> float:
    """Fraction of the keyframes of ``path`` (a :class:`KeyframePath`) whose position is inside ``truth``."""
    pos = np.array([k.position for k in path.keyframes])
    return float(np.mean(_inside(volume, truth, pos)))


def look_down_ratio(image) -> float:
    """Median depth of the frame's centre (middle 20 % box) over that of its border (outer 10 %); no hit = 1 m."""
    d = np.where(np.isfinite(image.depth), image.depth, NO_HIT_MM)
    h, w = d.shape
    c = d[int(0.4 * h):int(0.6 * h), int(0.4 * w):int(0.6 * w)]
    bh, bw = max(int(0.1 * h), 1), max(int(0.1 * w), 1)
    border = np.concatenate([d[:bh].ravel(), d[-bh:].ravel(), d[:, :bw].ravel(), d[:, -bw:].ravel()])
    return float(np.median(c) / max(float(np.median(border)), 1e-9))


def pixel_rays(camera, size) -> np.ndarray:
    """Unit world directions (H, W, 3) of a perspective camera's pixel centres for ``size = (width, height)``
    (the rays whose depths a renderer writes)."""
    w, h = size
    col, row = np.meshgrid(np.arange(w) + 0.5, np.arange(h) + 0.5)
    return camera.pixel_ray(size, col, row)[1]


@njit(cache=True, nogil=True)
def _first_hits(part, parts, w, eye, dirs, tmax, out):
    """:func:`first_hit` of the wall record ``w`` from ``eye`` (3,) along each of ``dirs`` (n, 3) into ``out``, for
    the rays of part ``part`` of ``parts`` (``volumen.jit.run_parts``)."""
    n_rays = dirs.shape[0]
    for n in range(part * n_rays // parts, (part + 1) * n_rays // parts):
        out[n] = first_hit(w, (eye[0], eye[1], eye[2]), (dirs[n, 0], dirs[n, 1], dirs[n, 2]), tmax)


class _Boundary:
    """A lumen mask's boundary: its wall field (for first hits) and signed distance's gradient (for normals)."""

    def __init__(self, volume, mask: np.ndarray):
        from ..lumen._drawn_wall import signed_distance
        from ..lumen._grow import _bbox
        from ..wall._field import WallField

        self.volume = volume
        self.wall = WallField.from_mask(volume, mask)
        box = _bbox(mask, 3)
        self.origin = np.array([s.start for s in box], float)
        sdf = signed_distance(mask[box], volume.spacing)
        self.grad = [np.gradient(sdf, axis=a) for a in range(3)]

    def normals(self, points: np.ndarray) -> np.ndarray:
        """Unit normals (n, 3) of the boundary at world ``points``."""
        from scipy import ndimage

        zyx = (self.volume.world_to_index(points)[:, ::-1] - self.origin).T
        g_zyx = [ndimage.map_coordinates(g, zyx, order=1, mode="nearest") for g in self.grad]
        g = np.stack(g_zyx[::-1], axis=1) @ np.linalg.inv(self.volume.affine[:3, :3])  # index-space to world
        return g / np.maximum(np.linalg.norm(g, axis=1, keepdims=True), 1e-12)

    def offsets(self, image, camera) -> np.ndarray:
        from ..wall._first_hit import NO_HIT, Wall

        w = self.wall
        dirs = pixel_rays(camera, image.depth.shape[::-1]).reshape(-1, 3)
        eye = np.asarray(camera.position, float)
        out = np.empty(len(dirs))
        run_parts(_first_hits, len(dirs), Wall(w.field, w.geometry, float(w.level), w.step), eye,
                  np.ascontiguousarray(dirs), float(self.volume.diagonal), out)
        depth = image.depth.reshape(-1).astype(float)
        keep = np.isfinite(depth) & (out < NO_HIT)
        cos = np.abs(np.sum(self.normals(eye + out[keep, None] * dirs[keep]) * dirs[keep], axis=1))
        return (depth[keep] - out[keep]) * cos / float(max(self.volume.spacing))


def wall_offsets(volume, mask: np.ndarray, image, camera) -> np.ndarray:
    """How far the drawn wall lies from ``mask``'s boundary, in voxels (largest spacing), for each pixel of
    ``image`` (seen by ``camera``) that hits both: (first-hit depth - the mask's distance along the ray) x the
    cosine of the ray's incidence on the mask's boundary."""
    return _Boundary(volume, mask).offsets(image, camera)


@dataclass(frozen=True)
class FlightScore:
    """The scores of one flythrough (see the module docstring); NaN where not measured.

    Attributes
    ----------
    dice : float
    keyframes_inside : float
        Fraction, 0..1.
    looking_down : float
        Fraction of sampled frames whose look-down ratio is at least :data:`LOOK_DOWN`.
    ratios : tuple of float
        Each sampled frame's look-down ratio.
    wall_within_voxel : float
        Fraction of wall pixels drawn within one voxel of the mask's boundary (along their rays).
    """

    dice: float
    keyframes_inside: float
    looking_down: float
    ratios: tuple[float, ...]
    wall_within_voxel: float = float("nan")

    def row(self) -> str:
        """One line: Dice, keyframes inside, frames looking down, wall within a voxel (percent)."""
        wall = "" if np.isnan(self.wall_within_voxel) else f", wall within 1 voxel {100 * self.wall_within_voxel:.1f} %"
        return (f"Dice {self.dice:.3f}, keyframes inside {100 * self.keyframes_inside:.0f} %, looking down "
                f"{100 * self.looking_down:.0f} %{wall}")


def score_flight(volume, truth: np.ndarray, flight, *, lumen: np.ndarray | None = None, frames: int = 12,
                 size=(48, 48)) -> FlightScore:
    """Score ``flight`` (a :class:`Flight` on ``volume``) against the true lumen ``truth``.

    ``lumen``: the lumen the flight was made from (Dice against ``truth``; its boundary is the one the wall
    must be drawn within a voxel of). ``frames`` frames of ``size`` (width, height) pixels are sampled evenly
    along the path.
    """
    poses = flight.path.play(frames=frames)
    ratios, offsets = [], []
    boundary = None if lumen is None else _Boundary(volume, lumen)
    for pose in poses:
        img = flight.endoscope.render(pose, size)
        ratios.append(look_down_ratio(img))
        if boundary is not None:
            offsets.append(boundary.offsets(img, flight.endoscope.camera(pose)))
    r = np.array(ratios)
    off = np.concatenate(offsets) if offsets else np.array([])
    return FlightScore(dice=dice(lumen, truth) if lumen is not None else float("nan"),
                       keyframes_inside=keyframes_inside(volume, truth, flight.path),
                       looking_down=float(np.mean(r >= LOOK_DOWN)), ratios=tuple(float(x) for x in r),
                       wall_within_voxel=float(np.mean(np.abs(off) <= 1.0)) if off.size else float("nan"))
