"""The benchmarks' data sets: real scans where the machine has them, and the whole-region CTs built for speed.

* ``aorta``: the VMTK aorta CTA (``vmtk-aorta/aorta.mha`` in :func:`volumen.data.shared_data`, uncalibrated
  scanner units 0..2570), resampled with ``scipy.ndimage.zoom`` (linear) to the asked size and converted to HU
  (:data:`AORTA_HU`) as int16: a cropped angiogram;
* ``abdomen``, ``chest``: :func:`volumen.data.phantom`'s whole-region CTs (HU), soft tissue in most rays;
* ``mri``: the MRI template of :func:`volumen.data.sample` (``mni-brain``, 301x370x316 uint8 at 0.5 mm) where
  installed, as it is or resampled;
* ``head``, ``torso``: the older phantoms;
* ``scan``: a file of the user's (``--scan``: any file or DICOM folder :func:`volumen.io.load` opens), turned to
  RAS+ axis order (:func:`load_scan`) and resampled to the benchmark's sizes (:data:`SCAN_SIZES`), so a scan the
  benchmark has not seen gets the same rows and ratios as its own CTs (issue 27's check).

:func:`ray_shares` says what share of a picture's rays cross the body and soft tissue: the quantity that
decides how much of a translucent preset's work is shaded samples (issue 27: a whole-abdomen CT has soft
tissue in 35-43 % of the picture, the aorta in a few per cent).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = ["aorta_path", "resampled", "upsampled_aorta", "hu_aorta", "load_dataset", "load_scan", "scan_datasets",
           "ray_shares", "CT_KINDS", "SCAN_SIZES", "SOFT_TISSUE_HU", "AORTA_OFFSET", "AORTA_HU"]

#: the data set kinds that are CTs (their ratios are the bars), as opposed to the MRI and the old phantoms
CT_KINDS = ("aorta", "abdomen", "chest")
#: the sizes (x, y, z voxels) a scan given with ``--scan`` is resampled to: those of the benchmark's own CTs
SCAN_SIZES = ((244, 202, 224), (366, 303, 336))
#: Hounsfield range of soft tissue (fat, muscle, organs, blood): low but non-zero opacity in translucent presets
SOFT_TISSUE_HU = (-200.0, 200.0)
#: the shift of the CT presets on the aorta scan's own units where a picture keeps them (the path-tracing bench,
#: the reference pictures): it puts the contrast-filled lumen (1600-2200) in the presets' vessel and bone range
AORTA_OFFSET = 1000.0
#: the aorta scan's units against Hounsfield units, ``value = zero + per_hu * HU``: its README gives soft tissue
#: at 200-300 and the contrast-filled lumen at 1600-2200, which a CT angiogram shows at about 50 and 400 HU.
#: Below about 0 HU the scan holds 0 (fat and air read as water). With the presets shifted by +1000 instead, soft
#: tissue classified as skin (-750 HU): an opaque, speckled picture that a real CT does not give.
AORTA_HU = {"zero": 15.0, "per_hu": 4.7}


def aorta_path() -> Path | None:
    """The VMTK aorta (found by :func:`volumen.data.shared_data`), or None."""
    from volumen.data import shared_data

    return shared_data("vmtk-aorta", "aorta.mha")


def resampled(src, size_xyz, dtype=None, **labels):
    """``src`` (a Volume) resampled (linear, ``scipy.ndimage.zoom``) to ``size_xyz`` voxels (x, y, z) over the same
    field of view, rounded to ``dtype`` (default: the source's): a Volume with the source's modality, units and
    name unless ``labels`` (``modality=``, ``units=``, ``name=``) say otherwise."""
    from scipy import ndimage

    from volumen.core import Volume

    shape = tuple(int(n) for n in size_xyz[::-1])
    factors = [m / n for m, n in zip(shape, src.shape, strict=True)]
    data = ndimage.zoom(np.asarray(src.data, np.float32), factors, order=1, output=np.float32)
    dtype = np.dtype(dtype or src.data.dtype)
    if dtype.kind in "iu":  # rounded into the type's range, not wrapped around
        info = np.iinfo(dtype)
        data = np.clip(np.rint(data), info.min, info.max)
    data = data.astype(dtype)
    ratio = [n / m for n, m in zip(src.shape, data.shape, strict=True)]  # z, y, x
    spacing = tuple(s * r for s, r in zip(src.spacing, ratio, strict=True))
    affine = np.asarray(src.affine, float) @ np.diag(ratio[::-1] + [1.0])
    labels = {"modality": src.modality, "units": src.units, "name": src.name, **labels}
    return Volume(data, spacing=spacing, affine=affine, **labels)


def upsampled_aorta(size_xyz):
    """The aorta scan resampled (linear) to ``size_xyz`` voxels (x, y, z), rounded to int16, in its own units: a
    Volume labelled HU + 1000, the shift the CT presets take on it (:data:`AORTA_OFFSET`; in HU: :func:`hu_aorta`)."""
    from volumen.io import load

    return resampled(load(aorta_path()), size_xyz, np.int16, modality="CT", units="HU+1000")


def hu_aorta(size_xyz):
    """:func:`upsampled_aorta` in Hounsfield units (:data:`AORTA_HU`), int16."""
    from volumen.core import Volume

    raw = upsampled_aorta(size_xyz)
    hu = (raw.data.astype(np.float32) - AORTA_HU["zero"]) / AORTA_HU["per_hu"]
    return Volume(np.rint(hu).astype(np.int16), spacing=raw.spacing, affine=raw.affine, modality="CT", units="HU",
                  name=raw.name)


def scan_datasets(paths, sizes=SCAN_SIZES) -> dict:
    """The data sets of scan files: ``"scan1-244x202x224" -> ("scan", (244, 202, 224), path)``, each file at each
    of ``sizes`` (x, y, z voxels; None: as it is, named ``"scan1-as-loaded"``). The names number the files in the
    order given and never carry a file or folder name, which can be a patient's."""
    out = {}
    for n, path in enumerate(paths, 1):
        for size in sizes:
            label = "as-loaded" if size is None else "x".join(str(int(v)) for v in size)
            out[f"scan{n}-{label}"] = ("scan", None if size is None else tuple(int(v) for v in size), str(path))
    return out


def load_scan(path, shape=None):
    """``(Volume, HU offset)`` of a scan file (offset None where it is not a CT in Hounsfield units:
    ``core.hu_offset``): its voxel axes turned to RAS+ order (``core.canonical``: permuted and flipped, not
    resampled, so the VTK peer, which takes RAS+ grids only, draws it too), resampled (linear) to ``shape``
    (x, y, z voxels; None: as it is), int16 where it is a CT (as the benchmark's own CTs). ``ValueError`` for a
    colour volume."""
    from volumen.core import canonical, hu_offset
    from volumen.io import load

    vol = load(path)
    if vol.is_color:
        raise ValueError("a colour volume: the benchmarks draw scalar scans (CT, MRI)")
    vol = canonical(vol)
    offset = hu_offset(vol)
    dtype = np.int16 if offset is not None else None
    if shape is None:
        if dtype is not None and vol.data.dtype != dtype:
            vol = resampled(vol, vol.shape[::-1], dtype)  # the same grid, rounded to int16
        return vol, offset
    return resampled(vol, shape, dtype), offset


def load_dataset(kind: str, shape, path=None):
    """``(Volume, HU offset)`` of a data set (offset None where the values are not HU-based); None where its
    source is missing. ``shape``: (nx, ny, nz) voxels (None: the MRI template or the scan as they are);
    ``path``: the file of a ``"scan"`` (:func:`load_scan`)."""
    from volumen.data import phantom

    if kind == "scan":
        return load_scan(path, shape)
    if kind in ("head", "torso", "abdomen", "chest"):
        return phantom(kind, size=tuple(shape[::-1])), 0.0
    if kind == "mri":
        from volumen.data import sample

        try:
            mri = sample("mni-brain")
        except Exception:  # noqa: BLE001 - the optional system package is missing: skip the data set
            return None
        same = shape is None or tuple(shape) == mri.shape[::-1]
        return (mri if same else resampled(mri, shape)), None
    if kind != "aorta":
        raise ValueError(f"unknown data set kind {kind!r}")
    if aorta_path() is None:
        return None
    return hu_aorta(shape), 0.0


def ray_shares(volume, offset, camera, size) -> dict:
    """``{"body", "soft"}``: the share of the picture's rays (``camera``, ``size``) that cross the body (a sample
    above -500 HU) and soft tissue (:data:`SOFT_TISSUE_HU`); empty for data not in HU (``offset`` None).

    Each is the fraction of pixels whose maximum intensity projection of the tissue's mask (0 / 1, trilinear)
    reaches one half: ray casting, the same rays as the picture's.
    """
    if offset is None:
        return {}
    from volumen.core import Scene, TransferFunction, Volume
    from volumen.render import render

    hu = volume.data.astype(np.float32) - np.float32(offset)
    out = {}
    for name, mask in (("body", hu > -500.0), ("soft", (hu >= SOFT_TISSUE_HU[0]) & (hu <= SOFT_TISSUE_HU[1]))):
        m = Volume(mask.astype(np.int16), spacing=volume.spacing, affine=volume.affine)
        scene = Scene(volume=m, transfer=TransferFunction.window_level(1.0, 0.5), mode="mip")
        value = render(scene, camera, size).value
        out[name] = float(np.mean(np.nan_to_num(value, nan=0.0) >= 0.5))
    return out
