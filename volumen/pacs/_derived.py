"""What volumen sends back to an archive, made with highdicom in the scan's own study: a DICOM SEG of a label
map or a lumen mask, and a secondary capture of a rendering.

Both need the scan as DICOM files (a series loaded from a folder or from the cache): the SEG references
each source image and holds one frame per source slice, the capture takes the patient and study from them.
Nothing here reads or writes patient identity beyond copying it from the source into the derived object,
as DICOM requires.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import LabelError

__all__ = ["source_images", "make_seg", "make_capture"]

_LPS = np.array([-1.0, -1.0, 1.0])


def _version() -> str:
    """volumen's version as installed (the package root imports higher layers; not imported here)."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("volumen")
    except PackageNotFoundError:
        return "unknown"

#: Type 2 attributes of the patient and study modules that highdicom copies from the source (empty if absent)
_TYPE2 = ("PatientName", "PatientID", "PatientBirthDate", "PatientSex", "StudyDate", "StudyTime", "StudyID",
          "ReferringPhysicianName", "AccessionNumber")


def source_images(volume) -> list:
    """The DICOM datasets of ``volume``'s series (from ``meta["source"]``), sorted like its slices.

    Raises
    ------
    LabelError
        The volume was not read from DICOM files (a phantom, a NIfTI...), or its files are gone.
    """
    import pydicom

    src, uid = volume.meta.get("source"), volume.meta.get("series_uid")
    if not src or not uid or volume.meta.get("format") != "dicom":
        raise LabelError(src, "a DICOM SEG or capture needs a scan read from DICOM files (a folder, or "
                              "dicomweb://...), to reference its images and study")
    paths = [Path(p) for p in (src if isinstance(src, list) else [src])]
    files = [q for p in paths for q in (sorted(p.rglob("*")) if p.is_dir() else [p]) if q.is_file()]
    found = []
    inverse = np.linalg.inv(volume.affine)
    for f in files:
        try:
            ds = pydicom.dcmread(f)
        except (pydicom.errors.InvalidDicomError, OSError):
            continue
        if str(ds.get("SeriesInstanceUID", "")) != uid or "ImagePositionPatient" not in ds:
            continue
        for keyword in _TYPE2:
            if keyword not in ds:
                setattr(ds, keyword, "")
        ras = np.asarray(ds.ImagePositionPatient, float) * _LPS
        k = (inverse @ np.append(ras, 1.0))[2]
        found.append((k, ds))
    if len(found) != volume.shape[0]:
        raise LabelError(src, f"holds {len(found)} files of series {uid} for {volume.shape[0]} slices: the SEG "
                              "needs one source image per slice")
    found.sort(key=lambda t: t[0])
    if not np.allclose([k for k, _ in found], np.arange(len(found)), atol=1e-3):
        raise LabelError(src, "the source images do not sit on the volume's slices (resampled or multi-frame?)")
    return [ds for _, ds in found]


def _description(number: int, name: str):
    import highdicom as hd
    from pydicom.sr.codedict import codes

    algorithm = hd.AlgorithmIdentificationSequence(name="volumen", version=_version(),
                                                   family=codes.cid7162.ArtificialIntelligence)
    return hd.seg.SegmentDescription(
        segment_number=number, segment_label=name[:64] or f"segment {number}",
        segmented_property_category=codes.cid7150.AnatomicalStructure,
        segmented_property_type=codes.SCT.BodyStructure,
        algorithm_type=hd.seg.SegmentAlgorithmTypeValues.AUTOMATIC, algorithm_identification=algorithm)


def make_seg(labels, volume, *, description: str = "volumen segmentation"):
    """A binary DICOM SEG of ``labels`` (a LabelMap on the volume's grid, or a bool mask ``[z, y, x]``).

    Parameters
    ----------
    labels : LabelMap or (z, y, x) bool/int array
        On ``volume``'s grid (``volumen.load_labels(path, like=volume)`` puts it there). A mask is one
        segment named ``lumen``.
    volume : Volume
        The scan, read from DICOM (its files are the SEG's source images).
    description : str
        The SEG's SeriesDescription.

    Returns
    -------
    pydicom.Dataset
        The SEG (new series in the scan's study), ready for :func:`volumen.pacs.send` or ``save_as``.
    """
    import highdicom as hd

    data = np.asarray(getattr(labels, "data", labels))
    names = dict(getattr(labels, "names", {}) or {})
    if data.dtype == bool:
        data, names = data.astype(np.uint8), {1: "lumen"}
    if data.shape != tuple(volume.shape[:3]):
        raise LabelError(None, f"labels of shape {data.shape} are not on the scan's grid {tuple(volume.shape[:3])} "
                               "(load them with like=scan)")
    values = [int(v) for v in np.unique(data) if v != 0]
    if not values:
        raise LabelError(None, "the labels are empty: nothing to put in a SEG")
    sources = source_images(volume)
    renumbered = np.zeros(data.shape, np.uint16)
    for number, v in enumerate(values, start=1):  # segment numbers 1..n in label order
        renumbered[data == v] = number
    segments = [_description(n, names.get(v, f"label {v}")) for n, v in enumerate(values, start=1)]
    return hd.seg.Segmentation(
        source_images=sources, pixel_array=renumbered, segmentation_type=hd.seg.SegmentationTypeValues.BINARY,
        segment_descriptions=segments, series_instance_uid=hd.UID(), series_number=900, sop_instance_uid=hd.UID(),
        instance_number=1, manufacturer="volumen", manufacturer_model_name="volumen",
        software_versions=_version(), device_serial_number="0", series_description=description[:64])


def make_capture(rgb, volume, *, description: str = "volumen rendering", orientation: tuple[str, str] = ("L", "F")):
    """A secondary capture (8-bit RGB) of a picture in the scan's study.

    Parameters
    ----------
    rgb : (H, W, 3) uint8 array, or a PNG / JPEG path
    volume : Volume
        The scan, read from DICOM (patient and study come from its first file).
    orientation : (str, str)
        PatientOrientation: the patient directions along the picture's rows and down its columns; the default
        is volumen's anterior view (the patient's left to the right, feet down).
    """
    import highdicom as hd
    from PIL import Image

    if isinstance(rgb, (str, Path)):
        rgb = np.asarray(Image.open(rgb).convert("RGB"))
    rgb = np.ascontiguousarray(np.asarray(rgb, np.uint8)[..., :3])
    first = source_images(volume)[0]
    return hd.sc.SCImage.from_ref_dataset(
        ref_dataset=first, pixel_array=rgb, photometric_interpretation=hd.PhotometricInterpretationValues.RGB,
        bits_allocated=8, coordinate_system=hd.CoordinateSystemNames.PATIENT, patient_orientation=orientation,
        series_instance_uid=hd.UID(),
        sop_instance_uid=hd.UID(), series_number=901, instance_number=1, manufacturer="volumen",
        manufacturer_model_name="volumen", software_versions=_version(), series_description=description[:64])
