"""``Image.depth`` for texture slicing: where the accumulated opacity first reaches 0.5.

The ray caster's depth of a composite pixel is the distance at which the
accumulated opacity reaches ``DEPTH_OPACITY = 0.5``, i.e. where the optical
depth ``tau = -ln(1 - A)`` from the eye reaches ``ln 2``. Optical depth adds up
in any order, so the slicing pass writes each fragment's ``tau``, ``tau z`` and
``tau z^2`` (``z`` its view depth from the first slab boundary) into a float
target with additive blending, whatever the colour's blending order, and the
sums so far are read back every few planes. The chunk of planes in which the
running ``tau`` crosses ``ln 2`` is found from those read-backs; inside it the
optical depth is taken as spread evenly over the interval with the chunk's
mean and variance of ``z`` (a single plane: its own depth; a sharp surface: a
narrow interval), which places the crossing. The view depth is then turned
into the distance along the pixel's ray (divided by ``cos(theta)`` for
perspective cameras).
"""

from __future__ import annotations

import numpy as np

__all__ = ["DepthFromOpticalDepth", "DEPTH_OPACITY", "pixel_cosines"]

DEPTH_OPACITY = 0.5


def pixel_cosines(camera, size) -> np.ndarray:
    """(H, W) cosine between each pixel's ray (through its centre, row 0 at the top) and the view direction."""
    w, h = size
    if camera.projection == "orthographic":
        return np.ones((h, w))
    t = np.tan(np.radians(camera.fov) / 2)
    sx = (np.arange(w) + 0.5 - 0.5 * w) / (0.5 * h) * t
    sy = (0.5 * h - np.arange(h) - 0.5) / (0.5 * h) * t
    return 1.0 / np.sqrt(1.0 + sx[None, :] ** 2 + sy[:, None] ** 2)


class DepthFromOpticalDepth:
    """Collects the optical-depth read-backs of one slicing pass and turns them into a depth map.

    Parameters
    ----------
    camera : Camera
    size : (width, height)
    bounds : (n + 1,) float, mm
        Slab boundaries of the planes (increasing view depth); moments are
        taken from ``bounds[0]``.
    back_to_front : bool
        Planes are drawn from the far end.
    """

    def __init__(self, camera, size, bounds, back_to_front: bool):
        self.camera = camera
        self.size = size
        self.bounds = np.asarray(bounds, float)
        self.back = back_to_front
        self.snaps: list[tuple[int, np.ndarray]] = []

    def add(self, drawn: int, moments: np.ndarray) -> None:
        """Record the sums ``(tau, tau z, tau z^2)`` (H, W, 3) after the first ``drawn`` planes drawn."""
        self.snaps.append((int(drawn), np.asarray(moments, np.float64)))

    def depth(self) -> np.ndarray:
        """(H, W) float32 mm along the view ray; inf where the opacity never reaches 0.5."""
        w, h = self.size
        n = len(self.bounds) - 1
        # cumulative sums from the near end at increasing boundaries
        if not self.back:
            zs = [self.bounds[0]] + [self.bounds[d] for d, _ in self.snaps]
            cum = [np.zeros((h, w, 3))] + [m for _, m in self.snaps]
        else:
            total = self.snaps[-1][1]
            pairs = [(self.bounds[n], total)] + [(self.bounds[n - d], total - m) for d, m in self.snaps]
            pairs.sort(key=lambda p: p[0])
            zs, cum = [p[0] for p in pairs], [p[1] for p in pairs]
        z = np.asarray(zs) - self.bounds[0]
        c = np.stack(cum)                                       # (m, H, W, 3)
        tau = c[..., 0]
        target = -np.log(1.0 - DEPTH_OPACITY)
        reached = tau >= target
        hit = reached.any(axis=0)
        i = np.clip(np.argmax(reached, axis=0), 1, len(z) - 1)
        lo = np.take_along_axis(c, (i - 1)[None, ..., None], 0)[0]
        hi = np.take_along_axis(c, i[None, ..., None], 0)[0]
        d = hi - lo                                             # the crossing chunk's own sums
        mass = np.maximum(d[..., 0], 1e-12)
        mean = d[..., 1] / mass
        half = 0.5 * np.sqrt(np.maximum(12.0 * (d[..., 2] / mass - mean ** 2), 0.0))
        a = np.clip(mean - half, z[i - 1], z[i])
        b = np.clip(mean + half, z[i - 1], z[i])
        frac = np.clip((target - lo[..., 0]) / mass, 0.0, 1.0)
        view_depth = self.bounds[0] + a + frac * (b - a)
        out = view_depth / pixel_cosines(self.camera, self.size)
        return np.where(hit, out, np.inf).astype(np.float32)
