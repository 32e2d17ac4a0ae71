"""Every file pydicom ships as test data, read by volumen and by SimpleITK, compared.

Run as a script (``python tests/io/dicom_corpus.py``) it prints the counts table that
README's Formats section quotes. Nothing is downloaded: the corpus is the files in
pydicom's installed ``data`` folder.
"""

from __future__ import annotations

import collections
import os
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pydicom
import SimpleITK as sitk

import volumen
from volumen.errors import VolumeReadError

__all__ = ["corpus_files", "Outcome", "examine", "DOCUMENTED_REFUSALS", "CONVENTIONS"]

RAS = np.array([-1.0, -1.0, 1.0])
DATA = Path(pydicom.__file__).parent / "data"
_NOT_DATA = {".py", ".pyc", ".json", ".txt", ".md", ".dump", ".icc", ".gz"}

#: files pydicom or SimpleITK decode that volumen refuses, with the reason (README's list)
DOCUMENTED_REFUSALS = {
    "badVR.dcm": "NumberOfFrames is '1A', not a number: the frame count is unknown (SimpleITK ignores it and "
                 "reads one frame)",
}

#: conventions where volumen and SimpleITK (GDCM) differ on purpose: name -> (why, SimpleITK value -> volumen's)
CONVENTIONS = {
    "MONOCHROME1": ("SimpleITK inverts MONOCHROME1 (stored v -> 2^BitsStored - 1 - v); volumen keeps the stored "
                    "values and shows them inverted",
                    lambda b, ds: _slope(ds) * (2 ** int(ds.BitsStored) - 1) + 2 * _intercept(ds) - b),
    "binary SEG": ("SimpleITK scales 1-bit segment pixels to 0/255; volumen keeps 0/1", lambda b, ds: b / 255.0),
    "RT dose": ("volumen applies DoseGridScaling (values in Gy); SimpleITK returns the stored values",
                lambda b, ds: b * float(ds.DoseGridScaling)),
}

#: files SimpleITK decodes differently from pydicom's reference values: compared with pydicom instead
SITK_DIFFERS = {
    "SC_rgb_rle_16bit": "16/32-bit RGB RLE: GDCM orders the byte segments differently from pydicom's reference",
    "SC_rgb_rle_32bit": "16/32-bit RGB RLE: GDCM orders the byte segments differently from pydicom's reference",
    "rtdose_expb": "32-bit big endian: SimpleITK's values are byte-garbled (its little-endian twin rtdose.dcm agrees)",
}

#: lossy JPEG: decoders (libjpeg, IJG in GDCM) may round the inverse DCT differently by one grey level
LOSSY_ATOL = 1.0
_LOSSY = {"1.2.840.10008.1.2.4.50", "1.2.840.10008.1.2.4.51"}


def _slope(ds) -> float:
    return float(ds.get("RescaleSlope", 1) or 1)


def _intercept(ds) -> float:
    return float(ds.get("RescaleIntercept", 0) or 0)


def _convention_of(ds) -> str:
    if str(ds.get("PhotometricInterpretation", "")).strip() == "MONOCHROME1":
        return "MONOCHROME1"
    if int(ds.get("BitsAllocated", 0) or 0) == 1:
        return "binary SEG"
    if "DoseGridScaling" in ds:
        return "RT dose"
    return ""


def corpus_files() -> list[Path]:
    """Every data file pydicom installs (test_files, charset_files, palettes), sorted."""
    files = [Path(r) / f for r, _, fs in os.walk(DATA) for f in fs if "__pycache__" not in r]
    return sorted(p for p in files if p.suffix.lower() not in _NOT_DATA and p.parent != DATA)


@dataclass
class Outcome:
    """What volumen, pydicom and SimpleITK make of one file."""

    name: str
    volume: volumen.Volume | None = None
    error: VolumeReadError | None = None
    untyped: str = ""                      # an exception that is not volumen's
    pydicom_decodes: bool = False
    sitk: sitk.Image | None = None
    disagreements: list[str] = field(default_factory=list)
    convention: str = ""                   # a CONVENTIONS key the comparison went through
    reference: str = "SimpleITK"           # or "pydicom" for SITK_DIFFERS files


def _pydicom_decodes(path: Path) -> bool:
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            ds = pydicom.dcmread(path, force=True)
            return ds.pixel_array.size > 0
    except Exception:  # noqa: BLE001 - any failure means "pydicom does not decode it"
        return False


def _sitk_image(path: Path) -> sitk.Image | None:
    if not _looks_like_image(path):
        return None
    try:
        return sitk.ReadImage(str(path))
    except RuntimeError:
        return None


def _looks_like_image(path: Path) -> bool:
    """Has pixel data: SimpleITK is only asked about such files."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            ds = pydicom.dcmread(path, force=True, specific_tags=["Rows", "PixelData"])
        return "Rows" in ds
    except Exception:  # noqa: BLE001
        return False


def _reference(out: Outcome, path: Path) -> np.ndarray:
    """SimpleITK's values ``[z, y, x(, c)]`` turned into volumen's convention (or pydicom's values)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ds = pydicom.dcmread(path, force=True)
    if any(key in out.name for key in SITK_DIFFERS):
        out.reference = "pydicom"
        scale = float(ds.DoseGridScaling) if "DoseGridScaling" in ds else _slope(ds)
        return ds.pixel_array.astype(np.float64).reshape(out.volume.data.shape) * scale + _intercept(ds)
    ref = sitk.GetArrayFromImage(out.sitk).astype(np.float64)
    out.convention = _convention_of(ds)
    if out.convention:
        ref = CONVENTIONS[out.convention][1](ref, ds)
    return ref


def _compare(out: Outcome, path: Path) -> None:
    """Shape, origin (RAS), spacing and values of volumen's volume against SimpleITK's image."""
    vol, img = out.volume, out.sitk
    ref = _reference(out, path)
    if ref.ndim == 2 or (ref.ndim == 3 and img.GetNumberOfComponentsPerPixel() > 1):
        ref = ref[None]
    if ref.shape != vol.data.shape:
        out.disagreements.append(f"shape {vol.data.shape} vs SimpleITK {ref.shape}")
        return
    if not np.allclose(vol.origin, np.array(img.GetOrigin()) * RAS, atol=1e-3):
        out.disagreements.append(f"origin {vol.origin} vs SimpleITK {np.array(img.GetOrigin()) * RAS}")
    # SimpleITK gives a single 2-D image a slice spacing of 1 mm; volumen's comes from SliceThickness
    axes = slice(0, 3) if vol.shape[0] > 1 else slice(1, 3)
    sp_ref = np.array(img.GetSpacing()[::-1] if img.GetDimension() == 3 else (1.0, *img.GetSpacing()[::-1]))
    if not np.allclose(np.array(vol.spacing)[axes], sp_ref[axes], rtol=1e-4):
        out.disagreements.append(f"spacing {vol.spacing} vs SimpleITK {tuple(sp_ref)}")
    lossy = vol.meta.get("transfer_syntax_uid") in _LOSSY
    tol = LOSSY_ATOL if lossy else 1e-4 * max(1.0, float(np.abs(ref).max()))
    err = float(np.abs(vol.data.astype(np.float64) - ref).max())
    if err > tol:
        out.disagreements.append(f"values differ by up to {err:g} (tolerance {tol:g})")


def examine(path: Path) -> Outcome:
    """Load ``path`` with volumen (typed error or volume) and compare with SimpleITK where it reads it."""
    out = Outcome(str(path.relative_to(DATA)))
    try:
        out.volume = volumen.load(path, format="dicom")
    except VolumeReadError as exc:
        out.error = exc
    except Exception as exc:  # noqa: BLE001 - recorded, the test fails on it
        out.untyped = f"{type(exc).__name__}: {exc}"
    out.pydicom_decodes = _pydicom_decodes(path)
    out.sitk = _sitk_image(path)
    if out.volume is not None and out.sitk is not None:
        _compare(out, path)
    return out


def table(outcomes: list[Outcome]) -> str:
    """Counts: loaded, agreeing with SimpleITK, conventions, typed refusals by error type."""
    loaded = [o for o in outcomes if o.volume is not None]
    both = [o for o in loaded if o.sitk is not None]
    refused = collections.Counter(type(o.error).__name__ for o in outcomes if o.error is not None)
    rows = [("files", len(outcomes)), ("loaded", len(loaded)),
            ("  colour", sum(o.volume.is_color for o in loaded)),
            ("  also read by SimpleITK", len(both)),
            ("  agree with SimpleITK", sum(not o.disagreements and not o.convention and o.reference == "SimpleITK"
                                           for o in both)),
            ("  agree after a documented convention", sum(not o.disagreements and bool(o.convention) for o in both)),
            ("  agree with pydicom (SimpleITK differs)", sum(not o.disagreements and o.reference == "pydicom"
                                                            for o in both)),
            ("  disagree", sum(bool(o.disagreements) for o in both)),
            ("typed refusals", sum(refused.values()))]
    rows += [(f"  {k}", v) for k, v in sorted(refused.items())]
    rows += [("  of which pydicom or SimpleITK decode (documented)",
              sum(o.error is not None and (o.pydicom_decodes or o.sitk is not None) for o in outcomes)),
             ("untyped errors", sum(bool(o.untyped) for o in outcomes))]
    return "\n".join(f"{k:52} {v}" for k, v in rows)


if __name__ == "__main__":
    results = [examine(p) for p in corpus_files()]
    for o in results:
        if o.disagreements or o.untyped or (o.error and (o.pydicom_decodes or o.sitk is not None)):
            print(o.name, o.disagreements, o.untyped, o.error)
    print(table(results))
