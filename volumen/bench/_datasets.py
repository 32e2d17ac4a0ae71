"""The benchmarks' data sets: real scans where the machine has them, and the whole-region CTs built for speed.

* ``aorta``: the VMTK aorta CTA (``vmtk-aorta/aorta.mha`` in :func:`volumen.data.shared_data`, uncalibrated
  scanner units 0..2570), resampled with ``scipy.ndimage.zoom`` (linear) to the asked size and converted to HU
  (:data:`AORTA_HU`) as int16: a cropped angiogram;
* ``abdomen``, ``chest``: :func:`volumen.data.phantom`'s whole-region CTs (HU), soft tissue in most rays;
* ``mri``: the MRI template of :func:`volumen.data.sample` (``mni-brain``, 301x370x316 uint8 at 0.5 mm) where
  installed, as it is or resampled;
* ``head``, ``torso``: the older phantoms;
* ``scan``: a file of the user's (``--scan``: any file or DICOM folder :func:`volumen.io.load` opens), turned to
  RAS+ axis order on an axis-aligned grid (:func:`read_scan`) and resampled to the benchmark's sizes
  (:data:`SCAN_SIZES`, :func:`scan_at`), so a scan the benchmark has not seen gets the same rows and ratios as
  its own CTs (the speed bars' check).

:func:`ray_shares` says what share of a picture's rays cross the body and soft tissue: the quantity that
decides how much of a translucent preset's work is shaded samples (a whole-abdomen CT has soft
tissue in 35-43 % of the picture, the aorta in a few per cent).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = ["aorta_path", "resampled", "upsampled_aorta", "hu_aorta", "load_dataset", "read_scan", "scan_at",
           "scan_datasets", "ray_shares", "CT_KINDS", "SCAN_SIZES", "SCAN_QUICK_SIZE", "SOFT_TISSUE_HU",
           "AORTA_OFFSET", "AORTA_HU"]

#: the data set kinds that are CTs (their ratios are the bars), as opposed to the MRI and the old phantoms
CT_KINDS = ("aorta", "abdomen", "chest")
#: the sizes (x, y, z voxels) a scan given with ``--scan`` is resampled to: those of the benchmark's own CTs
SCAN_SIZES = ((244, 202, 224), (366, 303, 336))
#: ... and with ``--quick``
SCAN_QUICK_SIZE = (61, 51, 56)
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


def _rounded(data, dtype) -> np.ndarray:
    """``data`` as ``dtype``: an integer type rounded, and clipped into its range rather than wrapped around."""
    dtype = np.dtype(dtype)
    if dtype.kind in "iu":
        info = np.iinfo(dtype)
        data = np.clip(np.rint(data), info.min, info.max)
    return np.asarray(data).astype(dtype, copy=False)


def resampled(src, size_xyz, dtype=None, **labels):
    """``src`` (a Volume) resampled (linear, ``scipy.ndimage.zoom``) to ``size_xyz`` voxels (x, y, z) over the same
    field of view, rounded to ``dtype`` (default: the source's): a Volume with the source's modality, units and
    name unless ``labels`` (``modality=``, ``units=``, ``name=``) say otherwise."""
    from scipy import ndimage

    from volumen.core import Volume

    shape = tuple(int(n) for n in size_xyz[::-1])
    factors = [m / n for m, n in zip(shape, src.shape, strict=True)]
    data = ndimage.zoom(np.asarray(src.data, np.float32), factors, order=1, output=np.float32)
    data = _rounded(data, dtype or src.data.dtype)
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


def scan_datasets(scans, sizes=SCAN_SIZES) -> dict:
    """The data sets of scans (:func:`read_scan`'s ``(Volume, offset)`` each):
    ``"scan1-244x202x224" -> ("scan", (244, 202, 224), scan)``, each scan at each of ``sizes`` (x, y, z voxels;
    None: as it is, named ``"scan1-as-loaded"``). The names number the scans in the order given and never carry
    a file or folder name, which can be a patient's."""
    out = {}
    for n, scan in enumerate(scans, 1):
        for size in sizes:
            label = "as-loaded" if size is None else "x".join(str(int(v)) for v in size)
            out[f"scan{n}-{label}"] = ("scan", None if size is None else tuple(int(v) for v in size), scan)
    return out


def _load(path, n: int):
    """The volume of scan file number ``n``: a folder of several DICOM series gives its series of most slices
    (a scanner's export: scouts, the axial series, reconstructions). Read errors become ``ValueError`` naming
    the scan by its number, not its path."""
    from volumen.errors import MultipleSeriesError, VolumenError
    from volumen.io import load

    try:
        try:
            return load(path)
        except MultipleSeriesError as exc:
            return load(path, series=max(exc.series, key=lambda s: s[2])[0])
    except VolumenError as exc:
        problem = str(getattr(exc, "problem", exc)).splitlines()[0]
        for name in sorted({str(path), str(Path(path).resolve()), Path(path).name}, key=len, reverse=True):
            problem = problem.replace(name, f"scan{n}")  # a reader's own message may quote the path
        raise ValueError(f"scan{n}: {problem}") from None


def read_scan(path, n: int = 1):
    """``(Volume, HU offset)`` of scan file number ``n`` (any file or DICOM folder :func:`volumen.io.load` opens)
    as the benchmarks take it; offset None where it is not a CT in Hounsfield units (``core.hu_offset``).

    Its voxel axes are turned to RAS+ order (``core.canonical``: permuted and flipped, not resampled) and laid on
    an axis-aligned grid of its spacing (an oblique or gantry-tilted scan's rotation and shear are dropped: the
    benchmarks time the samples, and VTK's peer takes axis-aligned RAS+ grids only). A CT is rounded to int16, as
    the benchmark's own CTs are. Named ``scan<n>``, its metadata dropped. ``ValueError`` (one line, no path) for
    a file that does not read, a colour volume or a slab (a single image, a few slices).
    """
    from volumen.core import Volume, canonical, hu_offset

    vol = _load(path, n)
    if vol.is_color or vol.thin_axis is not None:
        what = "a colour volume" if vol.is_color else f"a slab of {'x'.join(map(str, vol.shape[::-1]))} voxels"
        raise ValueError(f"scan{n}: {what}: the benchmarks draw scalar volumes (CT, MRI)")
    vol = canonical(vol)  # a lazy view of a chunked (OME-Zarr) volume: read when drawn at a size (scan_at)
    grid = np.diag([*vol.spacing[::-1], 1.0])
    grid[:3, 3] = np.asarray(vol.affine)[:3, 3]
    return Volume(vol.data, spacing=vol.spacing, affine=grid, modality=vol.modality, units=vol.units,
                  name=f"scan{n}"), hu_offset(vol)


def scan_at(scan, shape):
    """A scan (:func:`read_scan`) resampled (linear) to ``shape`` (x, y, z voxels; None: as it is), int16 where
    it is a CT. A source more than twice the size along an axis is first thinned to at most twice (every k-th
    sample), so a large CT does not need a float copy of its whole grid."""
    from volumen.core import Volume

    vol, offset = scan
    dtype = np.int16 if offset is not None else None
    step = [1, 1, 1] if shape is None else [max(1, n // (2 * m)) for n, m in zip(vol.shape, shape[::-1],
                                                                              strict=True)]  # z, y, x
    data = np.asarray(vol.data[::step[0], ::step[1], ::step[2]])
    if shape is None and dtype is not None:
        data = _rounded(data, dtype)
    vol = Volume(data, affine=np.asarray(vol.affine, float) @ np.diag([*step[::-1], 1.0]),
                 spacing=tuple(s * k for s, k in zip(vol.spacing, step, strict=True)), modality=vol.modality,
                 units=vol.units, name=vol.name)
    return (vol if shape is None else resampled(vol, shape, dtype)), offset


def load_dataset(kind: str, shape, scan=None):
    """``(Volume, HU offset)`` of a data set (offset None where the values are not HU-based); None where its
    source is missing. ``shape``: (nx, ny, nz) voxels (None: the MRI template or the scan as they are);
    ``scan``: a ``"scan"``'s :func:`read_scan` (:func:`scan_at`)."""
    from volumen.data import phantom

    if kind == "scan":
        return scan_at(scan, shape)
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
