"""DICOM pixels of one file -> stored or physical values, ``(frames, rows, cols)`` or colour ``(..., 3)``.

Decoding is pydicom's (its plugins: pylibjpeg with libjpeg / openjpeg / rle, pyjpegls,
gdcm, Pillow; pydicom tries each installed one in turn). On top of the decoded array:

* colour: RGB and YBR_* come back as RGB (pydicom converts YCbCr); PALETTE COLOR is
  expanded through its lookup table (``apply_color_lut``) to 8-bit RGB;
* a Modality LUT Sequence is applied here (``apply_modality_lut``); the linear
  RescaleSlope / RescaleIntercept is applied by the caller, per slice;
* FloatPixelData / DoubleFloatPixelData are read as float32 / float64.

MONOCHROME1 is returned as stored (the caller flags it for inverted display).
"""

from __future__ import annotations

import warnings

import numpy as np
import pydicom
from pydicom.errors import InvalidDicomError
from pydicom.uid import ExplicitVRLittleEndian, ImplicitVRLittleEndian

from ..errors import CorruptDataError, MissingDependencyError, SeriesError
from ._dicom_series import PIXEL_TAGS

__all__ = ["decode"]

_INSTALL = {
    "JPEG-LS": "pip install pyjpegls (or: pip install pylibjpeg pylibjpeg-libjpeg, or: pip install python-gdcm)",
    "JPEG 2000": "pip install pylibjpeg pylibjpeg-openjpeg (or: pip install python-gdcm)",
    "JPEG": "pip install pylibjpeg pylibjpeg-libjpeg (or: pip install python-gdcm)",
    "RLE": "pip install pylibjpeg pylibjpeg-rle",
}
_INSTALL_ANY = "pip install pylibjpeg pylibjpeg-libjpeg pylibjpeg-openjpeg (or: pip install python-gdcm)"


def _open(path: str):
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                ds = pydicom.dcmread(path)
            except InvalidDicomError:  # no preamble: accepted by the header pass for its DICOM suffix
                ds = pydicom.dcmread(path, force=True)
                if "TransferSyntaxUID" not in ds.file_meta:
                    ds.file_meta.TransferSyntaxUID = (ImplicitVRLittleEndian if ds.original_encoding[0]
                                                      else ExplicitVRLittleEndian)
    except Exception as exc:  # noqa: BLE001 - whatever pydicom raises, the file is unreadable
        raise CorruptDataError(path, f"is not a readable DICOM file ({type(exc).__name__})") from None
    if not any(tag in ds for tag in PIXEL_TAGS):
        raise CorruptDataError(path, "has no pixel data (truncated file?)")
    return ds


def _transfer_syntax(ds, path: str) -> str:
    """The transfer syntax's name for messages; raises when compressed data has no installed decoder."""
    ts = getattr(ds.get("file_meta", None), "TransferSyntaxUID", None)
    ts_name = f"{ts.name} ({ts})" if ts else "an unknown transfer syntax"
    if ts and ts.is_compressed and "PixelData" in ds:
        from pydicom.pixels import get_decoder

        try:
            available = get_decoder(ts).is_available
        except NotImplementedError:
            raise CorruptDataError(path, f"pixel data uses {ts_name}, which no pydicom decoder supports") from None
        if not available:
            hint = next((v for k, v in _INSTALL.items() if k in ts.name), _INSTALL_ANY)
            raise MissingDependencyError(path, f"pixel data is compressed with {ts_name} and no installed "
                                               f"decoder reads it; install one: {hint}")
    return ts_name


def _gdcm_pixels(path: str) -> np.ndarray | None:
    """Greyscale pixels decoded by GDCM itself, ``(frames, rows, cols)``; ``None`` when it cannot.

    pydicom's gdcm plugin refuses 12-bit JPEG Extended (Process 4), which GDCM decodes;
    this is the fallback for such files (greyscale only: colour stays with pydicom's
    YCbCr handling).
    """
    try:
        import gdcm
    except ImportError:
        return None
    reader = gdcm.ImageReader()
    reader.SetFileName(path)
    if not reader.Read():
        return None
    image = reader.GetImage()
    fmt = image.GetPixelFormat()
    dtype = _GDCM_TYPES.get(fmt.GetScalarTypeAsString())
    if dtype is None or fmt.GetSamplesPerPixel() != 1:
        return None
    dims = [image.GetDimension(i) for i in range(image.GetNumberOfDimensions())]
    cols, rows, frames = dims[0], dims[1], (dims[2] if len(dims) > 2 else 1)
    buffer = image.GetBuffer()
    if not buffer:
        return None
    raw = buffer.encode("utf-8", "surrogateescape")  # GDCM's SWIG returns bytes as str
    if len(raw) != rows * cols * frames * np.dtype(dtype).itemsize:
        return None
    return np.frombuffer(raw, dtype).reshape(frames, rows, cols).copy()


_GDCM_TYPES = {"UINT8": np.uint8, "INT8": np.int8, "UINT16": np.uint16, "INT16": np.int16,
               "UINT32": np.uint32, "INT32": np.int32, "FLOAT32": np.float32, "FLOAT64": np.float64}


def _decoded(ds, path: str) -> np.ndarray:
    """pydicom's decoded pixels; GDCM directly for compressed greyscale that pydicom's plugins refuse."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return ds.pixel_array
    except Exception:
        ts = getattr(ds.get("file_meta", None), "TransferSyntaxUID", None)
        arr = None
        if ts and ts.is_compressed and "PixelData" in ds:
            try:
                arr = _gdcm_pixels(path)
            except Exception:  # noqa: BLE001 - GDCM failing too: pydicom's error is the one to report
                arr = None
        if arr is None:
            raise
        return arr


def _values(ds, path: str, ts_name: str) -> np.ndarray:
    """Decoded pixels with colour made RGB and a Modality LUT Sequence applied."""
    from pydicom.pixels import apply_color_lut, apply_modality_lut

    photometric = str(ds.get("PhotometricInterpretation", "") or "").strip().upper()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            arr = _decoded(ds, path)
            if photometric == "PALETTE COLOR":
                arr = _to_8bit(apply_color_lut(arr, ds))
            elif "ModalityLUTSequence" in ds:
                arr = apply_modality_lut(arr, ds)
    except Exception as exc:  # noqa: BLE001
        raise CorruptDataError(path, f"could not decode its {ts_name} pixel data ({type(exc).__name__}: "
                                     f"{' '.join(str(exc).split())[:240]})") from None
    if arr.dtype.kind not in "iuf":
        raise SeriesError(path, f"pixel values of type {arr.dtype} are not a volume volumen reads")
    return arr


def _to_8bit(rgb: np.ndarray) -> np.ndarray:
    """Palette colours as 8-bit RGB: 16-bit LUT entries (full scale 0..65535) keep their high byte."""
    return (rgb >> 8).astype(np.uint8) if rgb.dtype == np.uint16 else rgb


def decode(path: str, frames: int | None, shape: tuple[int, int], samples: int) -> np.ndarray:
    """Pixel values of one file as ``(frames, rows, cols)``, or ``(frames, rows, cols, 3)`` RGB.

    ``frames`` is the number of frames the header pass found (``None`` for a single-frame
    file: one frame), ``shape`` the image's ``(rows, cols)``, ``samples`` 1 or 3 (the
    series' SamplesPerPixel after colour expansion). Raises CorruptDataError for an
    undecodable file, MissingDependencyError when no decoder is installed.
    """
    with warnings.catch_warnings():  # pydicom's warnings may quote element values
        warnings.simplefilter("ignore")
        ds = _open(path)
        ts_name = _transfer_syntax(ds, path)
        arr = _values(ds, path, ts_name)
    n = 1 if frames is None else frames
    frame_shape = (*shape, 3) if samples == 3 else shape
    if arr.shape == frame_shape:
        arr = arr[None]
    if arr.shape != (n, *frame_shape):
        raise CorruptDataError(path, f"pixel data has shape {arr.shape}, the header says {(n, *frame_shape)}")
    return arr
