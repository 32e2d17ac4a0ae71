"""Is this volume a CT in Hounsfield units? From its modality and units, else from its values.

A NIfTI or NRRD file carries no modality, so a CT opened from one looks like any other volume.
Its values give it away: Hounsfield units reaching about -1000 (air, or the scanner's padding
below it, -1024 or -3024 outside the field of view), a share of the voxels at air
(-1100..-900 HU), some at bone (>= 300 HU) and some between air and fat (lung, the edges of air). An MRI whose
resampler filled the outside of its field of view with -1000 has the first two (the fill, its bright tissue) but
not the last. A scan in scanner units (0..4095, air at 0), an
MRI (no negative values) or a PET (no air peak at -1000) is not taken for one. The test is
read on a strided sample of at most about 200,000 voxels (a few planes of a chunked volume).
"""

from __future__ import annotations

import numpy as np

from ._values import strided_values

__all__ = ["is_ct", "hu_offset", "AIR_HU", "BONE_HU", "BETWEEN_HU"]

#: the values of air in a CT (HU)
AIR_HU = (-1100.0, -900.0)
#: the values of cortical bone start here (HU)
BONE_HU = 300.0
_MIN_AIR = 0.005    # at least this share of the voxels at air
_MIN_BONE = 0.0005  # and this share at bone
_MIN_BETWEEN = 0.0005  # and this share between air and fat (lung, partial-volume edges): a fill of -1000 has none
#: between air and fat (HU): lung and the partial-volume edges of air, which every CT has (5-27 % of the voxels of
#: pydicom's CTs and the phantoms), and an MRI whose fill outside the field of view is -1000 or -1024 has not
BETWEEN_HU = (-900.0, -200.0)
_NOT_CT = ("MR", "PT", "NM", "US", "SEG", "RTDOSE", "XA", "DX", "CR", "MG")


def is_ct(volume) -> bool:
    """Whether ``volume`` holds a CT in Hounsfield units.

    True for modality ``CT`` or units in HU (``"HU"``, ``"HU+1000"``: see ``hu_offset``); False for a colour
    volume, another known modality (MR, PT, ...) or other units; otherwise decided from the values (module
    docstring).
    """
    modality = str(volume.modality or "").upper()
    units = str(volume.units or "")
    if modality == "CT" or units.upper().startswith("HU"):
        return True
    if volume.is_color or modality in _NOT_CT or units not in ("", "unknown"):
        return False
    v = strided_values(volume).astype(np.float64, copy=False)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return False
    air = np.count_nonzero((v >= AIR_HU[0]) & (v <= AIR_HU[1])) / v.size
    bone = np.count_nonzero(v >= BONE_HU) / v.size
    between = np.count_nonzero((v > BETWEEN_HU[0]) & (v < BETWEEN_HU[1])) / v.size
    return bool(v.min() <= AIR_HU[1] and air >= _MIN_AIR and bone >= _MIN_BONE and between >= _MIN_BETWEEN)


def hu_offset(volume) -> float | None:
    """How far a CT's stored values lie above Hounsfield units (``units`` ``"HU"``: 0, ``"HU+1000"``: 1000), None
    for a volume that is not CT (:func:`is_ct`)."""
    units = str(getattr(volume, "units", "") or "").replace(" ", "")
    if units.upper().startswith("HU"):
        rest = units[2:]
        try:
            return float(rest) if rest else 0.0
        except ValueError:
            return 0.0
    return 0.0 if is_ct(volume) else None
