"""Layout of the illumination volumes' meta rows and their planning constants (``_lightvol``, ``_lightsweep``).

The frame's scalar settings are fields of ``_frame.Settings``, not entries of a packed array.
"""

from __future__ import annotations

__all__ = ["NMETA", "NONE", "LATTICE", "DIRECT", "BUDGET", "NODE_SHARE", "MIN_NODES", "NEAR_STEPS", "MAX_STEP"]

# illumination volumes (``_lightvol``, ``_lightsweep``): one meta row per light
(LV_KIND, LV_OFF, LV_NK, LV_NV, LV_NU, LV_AXA, LV_AXB, LV_AXC, LV_PA, LV_PB, LV_PC, LV_KFAR, LV_K0, LV_OV, LV_OU,
 LV_H) = range(16)
NMETA = 16
NONE, LATTICE, DIRECT = 0, 1, 2
#: a lattice may hold at most this many times the nodes of the region at the requested resolution
BUDGET = 3.0
#: most values in one light's lattice per voxel of the volume (float32: a quarter of an int16 volume's bytes); coarser
#: spacing beyond ...
NODE_SHARE = 1.0 / 8.0
#: ... though never fewer than this many (16 MiB; below 32 M voxels this floor, not the share, bounds a lattice)
MIN_NODES = 2 ** 22
#: reference steps of each light path marched directly before the illumination volume is read: near the
#: sample, surfaces lie within one lattice spacing of the path, where any interpolated volume smears them
NEAR_STEPS = 3.0
#: largest index-space step between samples along a lattice ray before extra samples are taken
MAX_STEP = 1.75
