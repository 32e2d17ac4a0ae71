"""Segmentation files with their own names: 3D Slicer ``.seg.nrrd`` and DICOM SEG.

* ``.seg.nrrd``: a 3-D label map or a 4-D one with a leading list axis of layers
  (segments that overlap live in different layers); each segment's ``SegmentN_Name``,
  ``SegmentN_Color`` (0..1), ``SegmentN_LabelValue`` and ``SegmentN_Layer``. Segments are
  renumbered 1, 2, ... in the file's order; where layers overlap, the later segment wins
  (a warning says which).
* DICOM SEG (binary or fractional), read with highdicom; a fractional segment holds the
  voxels whose fraction is >= ``threshold``. With ``like=`` a scan read from DICOM, the SEG
  must reference that scan's series.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..core import LabelMap
from ..errors import LabelError, MissingDependencyError
from ._nrrd import _geometry

__all__ = ["read_seg_nrrd", "read_dicom_seg"]

_LPS_TO_RAS = np.diag([-1.0, -1.0, 1.0, 1.0])
_SWAP = np.eye(4)[[2, 1, 0, 3]]  # (slice, row, column) <-> (column, row, slice)


def _segments(header: dict) -> list[dict]:
    out, i = [], 0
    while f"Segment{i}_Name" in header or f"Segment{i}_ID" in header:
        name = header.get(f"Segment{i}_Name") or header.get(f"Segment{i}_ID")
        color = header.get(f"Segment{i}_Color")
        out.append({
            "name": str(name).strip(),
            "color": tuple(float(c) for c in str(color).split()[:3]) if color else None,
            "value": int(header.get(f"Segment{i}_LabelValue", i + 1)),
            "layer": int(header.get(f"Segment{i}_Layer", 0)),
        })
        i += 1
    return out


def read_seg_nrrd(path) -> LabelMap:
    """A 3D Slicer segmentation (``.seg.nrrd``, one or several layers) as one label map."""
    import nrrd

    path = Path(path)
    try:
        data, header = nrrd.read(str(path), index_order="C")
        warn: list[str] = []
        affine, axes = _geometry(header, warn)
    except (OSError, ValueError, KeyError, TypeError, nrrd.NRRDError) as e:
        raise LabelError(path, f"not a readable segmentation NRRD ({e.__class__.__name__}: {e})") from None
    # C-order spatial axes come as (i, j, k) = (column, row, slice): put them [z, y, x], layers last
    order = [axes[2], axes[1], axes[0]]
    data = np.moveaxis(np.asarray(data), order, [0, 1, 2])
    if data.ndim == 3:
        data = data[..., None]
    segments = _segments(header) or [{"name": f"label_{v}", "color": None, "value": int(v), "layer": 0}
                                     for v in np.unique(data) if v]
    out = np.zeros(data.shape[:3], np.uint8 if len(segments) < 256 else np.uint16)
    names, colors, overlaps = {}, {}, []
    for new, seg in enumerate(segments, start=1):
        if seg["layer"] >= data.shape[3]:
            raise LabelError(path, f"segment {seg['name']!r} is in layer {seg['layer']}, the file has "
                                   f"{data.shape[3]}")
        m = data[..., seg["layer"]] == seg["value"]
        if (out[m] != 0).any():
            overlaps.append(seg["name"])
        out[m] = new
        names[new] = seg["name"]
        if seg["color"] is not None:
            colors[new] = seg["color"]
    meta = {"source": str(path), "format": "Slicer segmentation", "layers": int(data.shape[3]), "warnings": warn}
    if overlaps:
        meta["warnings"].append(f"segments overlap across layers (shown as the later one): {', '.join(overlaps)}")
    spacing = tuple(np.linalg.norm(affine[:3, :3], axis=0)[::-1])
    return LabelMap(out, spacing, affine, names, colors, meta)


def read_dicom_seg(path, *, like=None, threshold: float = 0.5) -> LabelMap:
    """A DICOM SEG (binary or fractional) as a label map; ``like`` (a DICOM scan) must be its source series."""
    try:
        import highdicom as hd
    except ImportError:
        raise MissingDependencyError(path, "reading DICOM SEG needs highdicom (pip install highdicom)") from None
    path = Path(path)
    try:
        seg = hd.seg.segread(str(path))
    except (ValueError, AttributeError, KeyError, TypeError, OSError) as e:
        raise LabelError(path, f"not a readable DICOM SEG ({e.__class__.__name__}: {e})") from None
    if like is not None and like.meta.get("series_uid"):
        series = {str(s) for _, s, _ in seg.get_source_image_uids()}
        if series and like.meta["series_uid"] not in series:
            raise LabelError(path, f"segments another series ({', '.join(sorted(series))[:120]}), not the scan's "
                                   f"{like.meta['series_uid']}")
    numbers = list(seg.segment_numbers)
    try:
        vol = seg.get_volume(segment_numbers=numbers, combine_segments=False, skip_overlap_checks=True)
    except (ValueError, RuntimeError) as e:
        raise LabelError(path, f"the SEG's frames do not form a volume ({e})") from None
    arr = np.asarray(vol.array)
    if arr.ndim == 3:
        arr = arr[..., None]
    out = np.zeros(arr.shape[:3], np.uint8 if len(numbers) < 256 else np.uint16)
    names = {}
    fractional = np.issubdtype(arr.dtype, np.floating)
    for new, number in enumerate(numbers, start=1):
        m = arr[..., new - 1] >= threshold if fractional else arr[..., new - 1] > 0
        out[m] = new
        names[new] = str(seg.get_segment_description(number).segment_label)
    affine = _LPS_TO_RAS @ np.asarray(vol.affine, float) @ _SWAP
    spacing = tuple(np.linalg.norm(affine[:3, :3], axis=0)[::-1])
    meta = {"source": str(path), "format": f"DICOM SEG ({'fractional' if fractional else 'binary'})",
            "series_uid": str(seg.SeriesInstanceUID)}
    return LabelMap(out, spacing, affine, names, {}, meta)
