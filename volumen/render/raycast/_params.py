"""Layouts of the packed parameter arrays every kernel reads (one place, imported by all of them).

``prm`` float64 ``(N_PRM,)`` and ``iprm`` int64 ``(N_IPRM,)`` carry the scalar
settings of one frame; the indices below name their entries. Shading models
(``I_MODEL``) select the per-light term in ``_shade.shade``.
"""

from __future__ import annotations

__all__ = ["P_DS", "P_ET", "P_KA", "P_KD", "P_KS", "P_SHINE", "P_VMIN", "P_VSCALE", "P_ISO", "P_PRE_SCALE",
           "P_ISO_R", "P_DS0", "P_SH_OFF", "P_SH_STEP", "P_KEXT", "P_ALBEDO", "P_G", "N_PRM",
           "I_MODE", "I_NEAREST", "I_JITTER", "I_SEED", "I_SKIP", "I_BLOCK", "I_PREINT", "I_NLIGHTS", "I_GRADOP",
           "I_NPLANES", "I_SHADED", "I_MODEL", "I_BOUNCES", "N_IPRM", "M_PHONG", "M_SHADOWS", "M_SCATTER",
           "MODEL_CODES"]

# float parameters
(P_DS, P_ET, P_KA, P_KD, P_KS, P_SHINE, P_VMIN, P_VSCALE, P_ISO, P_PRE_SCALE, P_ISO_R) = range(11)
# P_ISO_R .. P_ISO_R + 2: the isosurface colour
P_DS0 = 14       # reference step ds0, mm
P_SH_OFF = 15    # shadow / light-path offset from the sample, mm
P_SH_STEP = 16   # direct shadow-ray step, mm
P_KEXT = 17      # extinction scale: sigma_t = P_KEXT * (-ln(1 - alpha)) / ds0
P_ALBEDO = 18    # single-scattering albedo sigma_s / sigma_t
P_G = 19         # Henyey-Greenstein anisotropy
N_PRM = 20
# integer parameters
(I_MODE, I_NEAREST, I_JITTER, I_SEED, I_SKIP, I_BLOCK, I_PREINT, I_NLIGHTS, I_GRADOP, I_NPLANES, I_SHADED,
 I_MODEL, I_BOUNCES) = range(13)
N_IPRM = 13

# shading models of ``shade``
M_PHONG, M_SHADOWS, M_SCATTER = 0, 1, 2
#: Shading.mode -> model code (none: unshaded; pathtrace uses the scattering medium)
MODEL_CODES = {"none": M_PHONG, "headlight": M_PHONG, "phong": M_PHONG, "shadows": M_SHADOWS,
               "scattering": M_SCATTER, "pathtrace": M_SCATTER}

# illumination volumes (``_lightvol``, ``_lightsweep``): one meta row per light
(LV_KIND, LV_OFF, LV_NK, LV_NV, LV_NU, LV_AXA, LV_AXB, LV_AXC, LV_PA, LV_PB, LV_PC, LV_KFAR, LV_K0, LV_OV, LV_OU,
 LV_H) = range(16)
NMETA = 16
NONE, LATTICE, DIRECT = 0, 1, 2
#: a lattice may hold at most this many times the nodes of the region at the requested resolution
BUDGET = 3.0
#: most values in one light's lattice (float32: 256 MB); coarser spacing beyond
MAX_NODES = 2 ** 26
#: reference steps of each light path marched directly before the illumination volume is read: near the
#: sample, surfaces lie within one lattice spacing of the path, where any interpolated volume smears them
NEAR_STEPS = 3.0
#: largest index-space step between samples along a lattice ray before extra samples are taken
MAX_STEP = 1.75
