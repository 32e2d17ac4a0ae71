"""Reading segmentations as label maps: :func:`load_labels`, and putting them on a scan's grid.

What is read (detected from the path):

* a folder of one mask per structure (TotalSegmentator's default output): each
  ``NAME.nii.gz`` (``.nii``, ``.nrrd``, ``.mha``, ``.mhd``) is the structure NAME,
  values 1, 2, ... in the files' sorted order;
* a Slicer ``.seg.nrrd`` (segment names, colours, label values, layers) and a DICOM
  SEG (binary or fractional, read with highdicom): :mod:`._labels_seg`;
* any integer volume :func:`volumen.load` reads (NIfTI, NRRD, MetaImage...) as a label
  map, its names from ``names=`` (a table :mod:`._labels_tables` reads) or a table
  beside it with the same stem (``.json``, ``.csv``, ``.txt``, ``.ctbl``, ``.label``), or with the image's name
  less ``.gz`` (MRIcron's ``aal.nii.txt`` beside ``aal.nii.gz``).

``like=volume`` resamples the labels onto the scan's grid (nearest voxel, through both
affines) and refuses labels that do not overlap it.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from ..core import LabelMap, Volume
from ..errors import LabelError, MissingPathError
from ._labels_tables import read_names_table

__all__ = ["load_labels", "resample_labels", "labels_on_grid", "MASK_SUFFIXES"]

MASK_SUFFIXES = (".nii.gz", ".nii", ".seg.nrrd", ".nrrd", ".mha", ".mhd")
_TABLE_SUFFIXES = (".json", ".csv", ".txt", ".ctbl", ".label")


def _stem(path: Path) -> str:
    name = path.name
    for s in MASK_SUFFIXES:
        if name.lower().endswith(s):
            return name[: -len(s)]
    return path.stem


def resample_labels(data: np.ndarray, affine, shape, target_affine) -> np.ndarray:
    """Integer labels ``[z, y, x]`` on the grid ``affine`` sampled at the voxel centres of the grid
    (``shape`` (z, y, x), ``target_affine``): nearest voxel, 0 outside ``data``'s grid."""
    from scipy import ndimage

    if tuple(data.shape) == tuple(shape) and np.allclose(affine, target_affine, atol=1e-4):
        return data
    ijk_to_ijk = np.linalg.inv(np.asarray(affine, float)) @ np.asarray(target_affine, float)
    perm = np.eye(4)[[2, 1, 0, 3]]  # (i, j, k) <-> (z, y, x)
    zyx = perm @ ijk_to_ijk @ perm
    # one voxel of zeros around, read with mode "nearest": a centre a rounding error off the edge keeps the edge
    # voxel (scipy's "constant" mode would drop it), whatever lies further out reads 0
    padded = np.pad(data, 1)
    return ndimage.affine_transform(padded, zyx[:3, :3], offset=zyx[:3, 3] + 1.0, output_shape=tuple(shape),
                                    order=0, mode="nearest")


def labels_on_grid(labels: LabelMap, volume: Volume) -> LabelMap:
    """``labels`` resampled onto ``volume``'s grid (nearest); :class:`LabelError` when none of them lands on it,
    a warning in ``meta['warnings']`` when some structure is cut off."""
    src = labels.meta.get("source")
    data = resample_labels(labels.data, labels.affine, volume.shape, volume.affine)
    if data is labels.data:
        return labels
    before, after = labels.counts(), np.bincount(data.ravel(), minlength=max(labels.values, default=0) + 1)
    if labels.data.any() and not data.any():
        raise LabelError(src, f"the labels' grid {labels.shape} (z, y, x) does not overlap the scan "
                              f"{volume.shape}: is it this scan's segmentation?")
    out = labels.with_data(data, volume.spacing, volume.affine)
    lost = [labels.names[v] for v, n in before.items() if n and after[v] == 0]
    if lost:
        msg = f"structures outside the scan: {', '.join(lost)}"
        out.meta["warnings"].append(msg)
        warnings.warn(f"{src}: {msg}", stacklevel=2)
    return out


def _names(path: Path, names) -> tuple[dict | None, Path | None]:
    if names is not None:
        return read_names_table(names), Path(names)
    # beside it with its stem (aal.txt) or, as MRIcron names its atlases' tables, its name less .gz (aal.nii.txt)
    stems = dict.fromkeys((_stem(path), path.name.removesuffix(".gz")))
    for f in (path.with_name(stem + s) for stem in stems for s in _TABLE_SUFFIXES):
        if f.exists():
            return read_names_table(f), f
    return None, None


def _label_file(path: Path, names) -> LabelMap:
    from . import load

    vol = load(path)
    data = np.asarray(vol.data)
    if vol.is_color or not np.issubdtype(data.dtype, np.integer) and not np.array_equal(data, np.round(data)):
        raise LabelError(path, f"not a label map: values must be whole numbers, the file holds {data.dtype} "
                               f"{'colour' if vol.is_color else 'fractions'}")
    if data.min() < 0 or data.max() > 65535:
        raise LabelError(path, f"label values must lie in 0..65535, found {data.min()}..{data.max()}")
    data = data.astype(np.uint16 if data.max() > 255 else np.uint8)
    table, table_path = _names(path, names)
    present = [int(v) for v in np.unique(data) if v]
    nm, col = {}, {}
    if table is not None:
        missing = [v for v in present if v not in table]
        if missing:
            raise LabelError(table_path, f"does not match {path.name}: label values "
                                         f"{', '.join(map(str, missing[:10]))} have no name in it")
        for v in present:
            nm[v] = table[v][0]
            if table[v][1] is not None:
                col[v] = table[v][1]
    meta = {"source": str(path), "format": "label map", "warnings": list(vol.meta.get("warnings", []))}
    if table_path is not None:
        meta["names_table"] = str(table_path)
    return LabelMap(data, vol.spacing, vol.affine, nm, col, meta)


def _mask_folder(folder: Path) -> LabelMap:
    from . import load

    files = sorted(p for p in folder.iterdir() if p.is_file() and p.name.lower().endswith(MASK_SUFFIXES))
    if not files:
        raise LabelError(folder, f"holds no mask files ({', '.join(MASK_SUFFIXES)})")
    first = load(files[0])
    data = np.zeros(first.shape, np.uint8 if len(files) < 256 else np.uint16)
    names, overlaps = {}, []
    for value, f in enumerate(files, start=1):
        vol = first if value == 1 else load(f)
        if vol.is_color:
            raise LabelError(f, "a colour image is not a mask")
        inside = (np.asarray(vol.data) > 0.5).astype(np.uint8)
        m = resample_labels(inside, vol.affine, first.shape, first.affine).astype(bool)
        if (data[m] != 0).any():
            overlaps.append(_stem(f))
        data[m] = value
        names[value] = _stem(f)
    meta = {"source": str(folder), "format": "mask folder"}
    if overlaps:
        meta["warnings"] = [f"masks overlap (later files win): {', '.join(overlaps[:10])}"]
    return LabelMap(data, first.spacing, first.affine, names, {}, meta)


def _is_dicom(path: Path) -> bool:
    try:
        with open(path, "rb") as f:
            return f.read(132)[128:132] == b"DICM"
    except OSError:
        return False


def load_labels(path, *, names=None, like: Volume | None = None, threshold: float = 0.5) -> LabelMap:
    """Read a segmentation as a :class:`~volumen.core.LabelMap` (names, colours, geometry).

    Parameters
    ----------
    path : str or Path
        A label map file, a Slicer ``.seg.nrrd``, a DICOM SEG file, or a folder of one mask per structure.
    names : str or Path, optional
        A names table (JSON, CSV, ITK-SNAP, Slicer colour table) for a plain label map.
    like : Volume, optional
        The scan: the labels are resampled onto its grid (nearest) and a DICOM SEG must reference its series.
    threshold : float
        Fractional DICOM SEG: a voxel belongs to a segment where its fraction is >= this (0..1).

    Raises
    ------
    LabelError
        Not a label map, a names table that does not match, no overlap with ``like``, a SEG of another series.
    """
    from ._labels_seg import read_dicom_seg, read_seg_nrrd

    path = Path(path)
    if not path.exists():
        raise MissingPathError(path, "no such file or folder")
    if path.is_dir():
        labels = _mask_folder(path)
    elif path.name.lower().endswith(".seg.nrrd"):
        labels = read_seg_nrrd(path)
    elif _is_dicom(path):
        labels = read_dicom_seg(path, like=like, threshold=threshold)
    else:
        labels = _label_file(path, names)
    return labels if like is None else labels_on_grid(labels, like)
