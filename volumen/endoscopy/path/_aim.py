"""Where the camera looks: at the farthest point of the centerline it can see down the lumen.

A keyframe that looks a fixed distance ahead along the centerline looks at the wall
in a bend of a wide lumen (a colon's flexure, the aortic arch): the point 10 mm ahead
lies off the line of sight down the lumen. :func:`aim_keyframes` turns each keyframe
toward the farthest centerline point (up to ``reach`` mm along it) that the eye sees
with the line of sight clear of the wall by half the lumen's radius at the eye (so the
middle of the picture is the lumen's far end, not the inner side of the bend it skims).
The line is checked every half voxel against the lumen's distance transform; a keyframe
that sees nothing so far ahead keeps its direction.
"""

from __future__ import annotations

import numpy as np

from ._keyframes import Keyframe, KeyframePath

__all__ = ["aim_keyframes"]


def _clearance(volume, lumen: np.ndarray):
    """A function: world points (n, 3) -> distance (mm) to the nearest voxel outside ``lumen``."""
    from scipy import ndimage

    from ..lumen._grow import _bbox

    box = _bbox(lumen, 1)
    dist = ndimage.distance_transform_edt(lumen[box], sampling=tuple(float(s) for s in volume.spacing))
    origin = np.array([s.start for s in box], float)

    def at(points):
        zyx = volume.world_to_index(np.asarray(points, float))[:, ::-1] - origin
        return ndimage.map_coordinates(dist, zyx.T, order=1, mode="constant", cval=0.0)

    return at


def _farthest(eye, arc, centerline, clear, need: float, reach: float, step: float):
    """The farthest centerline point within ``reach`` mm of arc after ``arc`` seen from ``eye`` with a line of
    sight at least ``need`` mm from the wall all along; None when not even the first is."""
    targets = centerline.at(np.arange(arc + 1.0, min(arc + reach, centerline.length) + 1e-9, 1.0))
    best = None
    for p in targets:
        n = max(int(np.ceil(np.linalg.norm(p - eye) / step)), 2)
        line = eye[None, :] + np.linspace(0.0, 1.0, n)[:, None] * (p - eye)[None, :]
        if np.min(clear(line[1:])) < need:
            break
        best = p
    return best


def aim_keyframes(path: KeyframePath, centerline, volume, lumen: np.ndarray, *, reach: float = 100.0
                  ) -> KeyframePath:
    """``path``'s keyframes (positions and up vectors kept), each looking at the farthest centerline point it
    sees down the ``lumen`` (bool mask on ``volume``'s grid); see the module docstring. ``reach`` in mm."""
    clear = _clearance(volume, np.asarray(lumen, bool))
    step = 0.5 * float(min(volume.spacing))
    keys = []
    for k in path.keyframes:
        eye = np.asarray(k.position, float)
        arc, _ = centerline.project(eye)
        need = 0.5 * float(centerline.radius_at(arc))
        target = _farthest(eye, arc, centerline, clear, need, reach, step)
        d = np.asarray(k.direction, float) if target is None or np.linalg.norm(target - eye) < 1.0 else target - eye
        up = np.asarray(k.up, float)
        if np.linalg.norm(np.cross(d / np.linalg.norm(d), up / np.linalg.norm(up))) < 1e-3:
            up = np.asarray(k.direction, float)  # never parallel to the view
        keys.append(Keyframe(tuple(eye), tuple(d), tuple(up)))
    return KeyframePath(keys, speed=path.speed)
