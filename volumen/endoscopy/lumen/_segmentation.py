"""An existing segmentation as the lumen: a label file, or a folder of one file per structure.

:func:`load_lumen_mask` reads what TotalSegmentator, 3D Slicer or ITK-SNAP write:

* a label map (NIfTI, NRRD, MetaImage, anything :func:`volumen.load` reads):
  ``label=N`` keeps the voxels equal to N, no label every non-zero voxel;
* a folder of per-structure masks (TotalSegmentator's ``segmentations/``):
  ``label=NAME`` reads ``NAME.nii.gz`` (or ``.nii``, ``.nrrd``, ``.mha``) in it.

A mask on another grid than the scan's is resampled onto the scan (nearest
voxel, through both affines, so a flipped or cropped grid is fine); a mask
whose grid does not overlap the scan, or whose structure falls outside it, is
refused with a :class:`~volumen.errors.LumenError` naming the file.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...errors import LumenError
from ...io import MASK_SUFFIXES as _SUFFIXES
from ...io import load, resample_labels

__all__ = ["load_lumen_mask", "resample_mask", "check_points_in_mask"]


def _structure_file(folder: Path, label) -> Path:
    if label is None or str(label).isdigit():
        raise LumenError(f"{folder}: a folder of masks needs --label NAME (one of its files' names)")
    for suffix in _SUFFIXES:
        f = folder / f"{label}{suffix}"
        if f.exists():
            return f
    names = sorted({p.name.split(".")[0] for p in folder.iterdir() if p.name.endswith(_SUFFIXES)})
    raise LumenError(f"{folder}: no mask named {label!r}; found: {', '.join(names[:20]) or 'none'}")


def resample_mask(mask: np.ndarray, mask_affine, volume) -> np.ndarray:
    """A bool mask ``[z, y, x]`` on the grid ``mask_affine`` (voxel i, j, k -> RAS mm) sampled at ``volume``'s
    voxel centres (nearest voxel; outside the mask's grid is False)."""
    m = np.asarray(mask, bool).view(np.uint8)
    return resample_labels(m, mask_affine, volume.shape, volume.affine).astype(bool)


def load_lumen_mask(file, volume, label=None) -> np.ndarray:
    """The lumen from a segmentation file or folder, on ``volume``'s grid.

    Parameters
    ----------
    file : str or Path
        A label file, or a folder of per-structure mask files.
    volume : Volume
        The scan the mask is put on.
    label : int, str or None
        Label value (files) or structure name (folders); None: every non-zero voxel.

    Returns
    -------
    (nz, ny, nx) bool

    Raises
    ------
    LumenError
        No such label or structure, or the mask does not overlap the scan.
    """
    file = Path(file)
    if file.is_dir():
        file, label = _structure_file(file, label), None
    seg = load(file)
    data = np.asarray(seg.data)
    if label is None:
        m = data != 0
    else:
        try:
            value = int(label)
        except ValueError:
            raise LumenError(f"{file}: --label {label!r} must be a number for a label file") from None
        m = data == value
        if not m.any():
            found = np.unique(data[data != 0])[:20]
            raise LumenError(f"{file}: no voxel has label {value}; labels present: "
                             f"{', '.join(str(int(v)) for v in found) or 'none'}")
    if not m.any():
        raise LumenError(f"{file}: the mask is empty")
    out = resample_mask(m, seg.affine, volume)
    if not out.any():
        raise LumenError(f"{file}: the mask does not overlap the scan (its grid {seg.shape} (z, y, x) lies "
                         f"elsewhere in space): is it the scan's segmentation?")
    return out


def check_points_in_mask(volume, mask: np.ndarray, points: dict, file) -> None:
    """Each named world point (``{"start": (x, y, z), ...}``, mm) must lie within 3 voxels of ``mask``, and all
    in one connected part of it; otherwise a :class:`LumenError` naming the point and ``file``."""
    from scipy import ndimage

    from ._find import _fmt, lumen_voxel, nearest_voxel

    labels, _ = ndimage.label(mask)
    parts = {}
    for name, p in points.items():
        lumen_voxel(volume, p, name)
        near = nearest_voxel(volume, mask, p)
        gap = float(np.linalg.norm(volume.index_to_world(np.asarray(near[::-1], float)) - np.asarray(p, float)))
        if gap > 3.0 * max(volume.spacing):
            raise LumenError(f"{file}: the {name} point {_fmt(p)} is not in the lumen mask (its nearest voxel is "
                             f"{gap:.1f} mm away)")
        parts[name] = int(labels[near])
    if len(set(parts.values())) > 1:
        first, *others = parts
        raise LumenError(f"{file}: the {others[0]} point {_fmt(points[others[0]])} lies in a part of the mask that "
                         f"does not connect to the {first} point's {_fmt(points[first])}")
