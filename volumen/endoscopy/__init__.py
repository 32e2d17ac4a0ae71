"""Virtual endoscopy: lumens, centerlines, collision detection, navigation, flythroughs, unfolded views.

* :func:`lumen_mask` -- region growing from a seed over a value range (air, contrast);
* :func:`find_lumen`, :func:`estimate_lumen` -- the lumen from a start (and end) point alone: its
  polarity (air or contrast), value range and wall threshold from the point's neighbourhood and rays cast
  from it, grown with explosion control, tagged fluid joined, thin bridges cut;
* :func:`estimate_from_mask`, :class:`LumenWall`, :func:`lumen_wall`, :func:`checked_centerline` -- the wall
  a flythrough draws (the data held to the lumen mask, or the mask's own boundary), from a segmentation or a
  grown lumen; centerlines refused when they detour through a leak;
* :func:`smooth_wall`, :func:`locally_thresholded` -- a grown lumen redrawn at local half-way values, drawn as
  its smoothed boundary where the values inside it vary more than its threshold allows;
* :func:`score_flight`, :class:`FlightScore` -- Dice, keyframes inside, frames looking down the lumen, the wall
  drawn against a mask's: the scores the tests and reports use;
* :func:`compute_centerline` -> :class:`Centerline` -- minimal path kept away from the wall,
  smoothed, resampled every ``step`` mm, with the local radius and rotation-minimizing frames;
* :class:`WallField`, :class:`Collider` -- where the wall is; moves that stop at a safety margin
  and slide along the wall;
* :class:`Pose`, :class:`ManualNavigator`, :class:`GuidedNavigator`, :class:`Keyframe`,
  :class:`KeyframePath` -- manual, guided and automatic navigation (no GUI);
* :class:`Endoscope`, :class:`FrameLog`, :class:`VideoWriter` -- rendering and writing flythroughs;
* :class:`Flight` -- keyframes, endoscope settings and centerline saved together, reproducing every frame;
* :func:`unfold` -> :class:`Unfolded` -- the wall cut open along the centerline;
* :func:`curved_reformation` -> :class:`CPR`, :func:`cross_section`, :func:`cpr_figure` -- straightened and
  stretched curved planar reformations along the centerline, with cross-sections.

Numba kernels compile (or load from Numba's cache) on first use, not at import.
"""

from .flight._endoscope import ENDOSCOPY_PRESETS, Endoscope, FrameLog, endoscopy_transfer
from .flight._from_points import checked_centerline, lumen_wall, make_flight
from .flight._saved import Flight
from .flight._scores import FlightScore, dice, keyframes_inside, look_down_ratio, score_flight, wall_offsets
from .flight._video import VideoWriter
from .lumen._drawn_wall import LumenWall
from .lumen._find import AIR_RANGE, CONTRAST_RANGE, find_lumen, lumen_mask, lumen_voxel, nearest_voxel
from .lumen._local_wall import locally_thresholded, smooth_wall
from .lumen._mask_estimate import estimate_from_mask
from .lumen._point_estimate import LUMEN_KINDS, LumenEstimate, estimate_lumen
from .lumen._segmentation import check_points_in_mask, load_lumen_mask
from .path._aim import aim_keyframes
from .path._centerline import Centerline, compute_centerline
from .path._collision import Collider, MoveResult
from .path._keyframes import Keyframe, KeyframePath, catmull_rom
from .path._navigation import GuidedNavigator, ManualNavigator
from .path._pose import Pose, slerp
from .views._cpr import CPR, cpr_width, cross_section, curved_reformation
from .views._cpr_figure import cpr_figure, vessel_window
from .views._unfold import Unfolded, WallLook, unfold
from .wall._field import WallField

__all__ = [
    "lumen_mask",
    "find_lumen",
    "lumen_voxel",
    "nearest_voxel",
    "load_lumen_mask",
    "check_points_in_mask",
    "estimate_lumen",
    "LumenEstimate",
    "estimate_from_mask",
    "LumenWall",
    "lumen_wall",
    "smooth_wall",
    "locally_thresholded",
    "checked_centerline",
    "make_flight",
    "score_flight",
    "FlightScore",
    "dice",
    "keyframes_inside",
    "look_down_ratio",
    "wall_offsets",
    "LUMEN_KINDS",
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
    "aim_keyframes",
    "catmull_rom",
    "Endoscope",
    "Flight",
    "FrameLog",
    "ENDOSCOPY_PRESETS",
    "endoscopy_transfer",
    "VideoWriter",
    "Unfolded",
    "unfold",
    "WallLook",
    "CPR",
    "curved_reformation",
    "cross_section",
    "cpr_figure",
    "cpr_width",
    "vessel_window",
]
