"""A small greyscale picture of a series: its middle instance, fetched into memory, windowed and shrunk.

Works the same over DICOMweb and DIMSE (one instance through the protocol's own retrieve); nothing is
written to the cache. Series without pixels (SEG is shown, SR and the like are not) give None.
"""

from __future__ import annotations

import warnings

import numpy as np

from ._api import connect

__all__ = ["thumbnail", "window_to_uint8"]


def window_to_uint8(frame: np.ndarray, center: float | None = None, width: float | None = None) -> np.ndarray:
    """``frame`` mapped to 0..255 through a window (default: the 1st..99th percentile of the values)."""
    frame = np.asarray(frame, np.float64)
    if center is None or width is None or width <= 0:
        lo, hi = np.percentile(frame, [1, 99])
    else:
        lo, hi = center - width / 2, center + width / 2
    if hi <= lo:
        hi = lo + 1.0
    return np.clip((frame - lo) / (hi - lo) * 255.0, 0, 255).astype(np.uint8)


def _first(value):
    try:
        return float(value[0] if hasattr(value, "__len__") and not isinstance(value, str) else value)
    except (TypeError, ValueError, IndexError):
        return None


def _picture(ds, size: int) -> np.ndarray | None:
    if "PixelData" not in ds:
        return None
    with warnings.catch_warnings():  # pydicom's warnings may quote element values
        warnings.simplefilter("ignore")
        pixels = np.asarray(ds.pixel_array)
    if pixels.ndim == 4 or (pixels.ndim == 3 and int(ds.get("SamplesPerPixel", 1)) == 1):
        pixels = pixels[len(pixels) // 2]
    if pixels.ndim == 3:  # colour: its luminance
        pixels = pixels[..., :3] @ np.array([0.299, 0.587, 0.114])
    values = pixels * float(ds.get("RescaleSlope", 1) or 1) + float(ds.get("RescaleIntercept", 0) or 0)
    grey = window_to_uint8(values, _first(ds.get("WindowCenter")), _first(ds.get("WindowWidth")))
    if ds.get("PhotometricInterpretation") == "MONOCHROME1":
        grey = 255 - grey
    step = max(1, int(np.ceil(max(grey.shape) / size)))
    return np.ascontiguousarray(grey[::step, ::step])


def thumbnail(server, study_uid: str, series_uid: str, *, size: int = 64, protocol: str | None = None,
              ask=None) -> np.ndarray | None:
    """A uint8 picture ``(rows, cols)``, at most ``size`` pixels on a side, of the series' middle instance.

    Returns None for a series without pixel data. Raises the archive's typed errors.
    """
    with connect(server, protocol=protocol, ask=ask) as archive:
        uids = archive.list_instances(study_uid, series_uid)
        if not uids:
            return None
        got = []
        archive.fetch(study_uid, series_uid, [uids[len(uids) // 2]], got.append, lambda: bool(got))
    return _picture(got[0], size) if got else None
