"""Virtual endoscopy: lumens, centerlines, collision detection, navigation, flythroughs, unfolded views.

* :func:`lumen_mask` -- region growing from a seed over a value range (air, contrast);
* :func:`compute_centerline` -> :class:`Centerline` -- minimal path kept away from the wall,
  smoothed, resampled every ``step`` mm, with the local radius and rotation-minimizing frames;
* :class:`WallField`, :class:`Collider` -- where the wall is; moves that stop at a safety margin
  and slide along the wall;
* :class:`Pose`, :class:`ManualNavigator`, :class:`GuidedNavigator`, :class:`Keyframe`,
  :class:`KeyframePath` -- manual, guided and automatic navigation (no GUI);
* :class:`Endoscope`, :class:`FrameLog`, :class:`VideoWriter` -- rendering and writing flythroughs;
* :func:`unfold` -> :class:`Unfolded` -- the wall cut open along the centerline.

Numba kernels compile (or load from Numba's cache) on first use, not at import.
"""

from ._centerline import Centerline, compute_centerline
from ._collision import Collider, MoveResult
from ._flythrough import ENDOSCOPY_PRESETS, Endoscope, FrameLog, endoscopy_transfer
from ._keyframes import Keyframe, KeyframePath, catmull_rom
from ._lumen import AIR_RANGE, CONTRAST_RANGE, lumen_mask
from ._navigation import GuidedNavigator, ManualNavigator
from ._pose import Pose, slerp
from ._unfold import Unfolded, unfold
from ._video import VideoWriter
from ._wall import WallField

__all__ = [
    "lumen_mask",
    "AIR_RANGE",
    "CONTRAST_RANGE",
    "Centerline",
    "compute_centerline",
    "WallField",
    "Collider",
    "MoveResult",
    "Pose",
    "slerp",
    "ManualNavigator",
    "GuidedNavigator",
    "Keyframe",
    "KeyframePath",
    "catmull_rom",
    "Endoscope",
    "FrameLog",
    "ENDOSCOPY_PRESETS",
    "endoscopy_transfer",
    "VideoWriter",
    "Unfolded",
    "unfold",
]
