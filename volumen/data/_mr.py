"""The MR head phantom: the head phantom's anatomy as an MRI, with a few voxels far brighter than any tissue.

An MRI is not in physical units: its values are the scanner's (here 0 to about 600 in tissue: soft tissue and
grey matter bright, white matter, CSF and fat darker, cortical bone dark, air 0; a contrast like proton
density's, chosen so partial-volume edges cannot ring: :data:`SIGNAL`, the marker bead aside) and its noise is
Rician (the magnitude of a complex signal with Gaussian noise in each channel, so the background is not 0 but a
low floor). Real scans also hold a few voxels far past the brightest tissue: inflow in a vessel, a ringing or
motion artefact, a marker capsule, a template's resampling overshoot. Those *outliers* are the failure class this
phantom is for: defaults spanned to the data's maximum (a data-relative transfer function, the first slice
window, the isosurface level) put the tissue low on their ramp, and the picture comes out dark and foggy
(``core._display``). ``outliers`` is their share of the head's voxels, each ``gain`` times the brightest tissue
(times 0.8-1.2); 0 makes none. ``dtype`` ``"float32"`` keeps the signal as floats, unrounded and unclipped, as a
processing pipeline writes an MRI: with a large ``gain`` its outliers then lie thousands of times past the tissue,
the failure class of a table and samples spanned to the maximum (``core.table_range``).

Built from the head phantom's Hounsfield units (``_head``, without its CT noise): each tissue's value is mapped
to an MR signal by a table (:data:`SIGNAL`), linearly between, so partial-volume edges stay edges. Deterministic
for a given size and seed. ``meta["truth"]``: the head phantom's, and ``tissue_max`` (the brightest tissue's
signal, the marker bead not counted).
"""

from __future__ import annotations

import numpy as np

from ..core import Volume
from ._head import head

__all__ = ["mr_head", "SIGNAL"]

#: Hounsfield units of the head phantom's tissues -> MR signal (scanner units), rising with HU up to soft tissue
#: and falling from there to bone: every edge between two tissues then blends monotonically from one signal to
#: the other, as an MRI's partial volume does (a table that went up and down between neighbours, like fat bright
#: and CSF dark in T1, would give a partial-volume voxel the signal of a third tissue: rings on every surface)
SIGNAL = ((-1000.0, 0.0),    # air
      (-100.0, 250.0),   # fat
      (5.0, 300.0),      # ventricles (CSF)
      (8.0, 310.0),      # CSF
      (27.0, 450.0),     # white matter
      (40.0, 560.0),     # grey matter, skin
      (45.0, 600.0),     # soft tissue (muscle)
      (80.0, 550.0),     # lens
      (1050.0, 200.0),   # diploe (marrow)
      (1700.0, 40.0),    # cortical bone
      (2000.0, 900.0))   # the marker bead: a capsule, bright in MR (the one exception: a small sphere on the skin)


def mr_head(size=None, *, noise: float = 12.0, outliers: float = 0.0005, gain: float = 4.0, seed: int = 0,
            dtype: str = "uint16") -> Volume:
    """Build the MR head phantom (see the module docstring); ``size`` as the head phantom's. ``noise``: the
    Gaussian sigma of each channel before the magnitude (signal units); ``dtype``: ``"uint16"`` (rounded, clipped
    to 0..65535) or ``"float32"``."""
    if not 0.0 <= outliers < 0.1:
        raise ValueError(f"outliers must be a share of the head's voxels in [0, 0.1), got {outliers}")
    if dtype not in ("uint16", "float32"):
        raise ValueError(f"dtype must be 'uint16' or 'float32', got {dtype!r}")
    ct = head(size, noise=0.0, seed=seed)
    hu, signal = np.asarray(SIGNAL, float).T
    s = np.interp(np.asarray(ct.data, np.float32), hu, signal).astype(np.float32)
    rng = np.random.default_rng(seed)
    s = np.hypot(s + rng.normal(0.0, noise, s.shape).astype(np.float32),
                 rng.normal(0.0, noise, s.shape).astype(np.float32))
    tissue_max = float(signal[:-1].max())  # the marker bead last: not tissue
    inside = np.flatnonzero(np.asarray(ct.data) > -500)
    picked = rng.choice(inside, size=int(round(outliers * inside.size)), replace=False)
    s.flat[picked] = gain * tissue_max * rng.uniform(0.8, 1.2, picked.size)
    data = s if dtype == "float32" else np.clip(np.rint(s), 0, 65535).astype(np.uint16)
    truth = dict(ct.meta.get("truth", {}), tissue_max=tissue_max)
    return Volume(data, spacing=ct.spacing, affine=ct.affine, modality="MR", units="", name="mr_head",
                  meta={"truth": truth})
