"""Environment maps: equirectangular HDR pictures (Radiance ``.hdr``, OpenEXR ``.exr``) read with imageio.

imageio reads both through its FreeImage plugin, which loads the system's FreeImage library (Debian's
``libfreeimage3``, installed by ``make system-libs``); where it is missing the error says so.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..errors import CorruptDataError, MissingDependencyError, MissingPathError, UnknownFormatError

__all__ = ["read_environment", "ENVIRONMENT_SUFFIXES"]

#: file suffix -> imageio format
ENVIRONMENT_SUFFIXES = {".hdr": "HDR-FI", ".exr": "EXR-FI"}


def read_environment(path: str | os.PathLike) -> np.ndarray:
    """Linear radiance ``(H, W, 3)`` float32 of an equirectangular environment map (row 0 the zenith).

    Raises
    ------
    MissingPathError, UnknownFormatError, MissingDependencyError, CorruptDataError
        No such file; not ``.hdr`` / ``.exr``; FreeImage missing; not a readable RGB picture of finite values.
    """
    p = Path(path)
    if not p.is_file():
        raise MissingPathError(p, "no such environment map")
    fmt = ENVIRONMENT_SUFFIXES.get(p.suffix.lower())
    if fmt is None:
        raise UnknownFormatError(p, f"an environment map is {' or '.join(ENVIRONMENT_SUFFIXES)} (equirectangular)")
    import imageio.v2 as iio

    try:
        img = np.asarray(iio.imread(p, format=fmt), dtype=np.float32)
    except RuntimeError as exc:
        if "freeimage" in str(exc).lower():
            raise MissingDependencyError(p, "reading HDR / EXR pictures needs the FreeImage library "
                                            "(Debian: apt-get install libfreeimage3)") from None
        raise CorruptDataError(p, f"not a readable {p.suffix} picture ({exc})") from None
    except (OSError, ValueError) as exc:
        raise CorruptDataError(p, f"not a readable {p.suffix} picture ({exc})") from None
    if img.ndim == 2:
        img = np.repeat(img[..., None], 3, axis=-1)
    if img.ndim != 3 or img.shape[2] < 3 or min(img.shape[:2]) < 2:
        raise CorruptDataError(p, f"an environment map is an (H, W, 3) picture, got shape {img.shape}")
    img = img[..., :3]
    if not np.all(np.isfinite(img)) or (img < 0).any():
        raise CorruptDataError(p, "an environment map holds finite radiance >= 0")
    return np.ascontiguousarray(img)
