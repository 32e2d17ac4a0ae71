"""Field edits of binary headers: NIfTI-1, NumPy ``.npy``/``.npz``, DICOM, and raw-file options.

NIfTI fields are edited at their offsets in nibabel's header dtype (a ``.gz`` file is
inflated, edited and deflated again, so the edit reaches the header). ``.npy`` edits
rewrite the header's dict literal; ``.npz`` edits apply an ``.npy`` edit to one member.
DICOM edits delete, empty, set or mix data elements through pydicom; when pydicom
cannot parse or write the seed, the mutation falls back to a bit flip.
"""

from __future__ import annotations

import gzip
import io
import random
import zipfile

import numpy as np

from ._mutate import bit_flips

__all__ = ["nifti_field", "npy_field", "npz_member", "dicom_field", "raw_options"]

_NIFTI_VALUES = {
    "sizeof_hdr": (0, -1, 540, 1 << 30), "dim": (-1, 0, 1, 2, 7, 8, 100, 32767, -32768),
    "datatype": (0, 1, 2, 4, 8, 16, 32, 64, 128, 255, 256, 512, 768, 1024, 1280, 1536, 1792, 2048, 2304, 9999),
    "bitpix": (0, 1, 7, 64, 999), "vox_offset": (-1.0, 0.0, 1e30, float("nan"), float("inf"), 1e9, 351.0),
    "pixdim": (0.0, -1.0, float("nan"), float("inf"), 1e38, 1e-38),
    "scl_slope": (float("inf"), float("nan"), 1e38, -1e38, 0.0, 1e-38),
    "scl_inter": (float("inf"), float("nan"), 1e38, -1e38),
    "qform_code": (-1, 0, 1, 5, 999), "sform_code": (-1, 0, 1, 5, 999),
    "quatern_b": (2.0, float("nan"), -1.0), "quatern_c": (2.0, float("nan")), "quatern_d": (2.0, float("inf")),
    "qoffset_x": (float("nan"), 1e38), "srow_x": (0.0, float("nan"), 1e38, float("inf")),
    "srow_y": (0.0, float("nan")), "srow_z": (0.0, float("nan"), 1e38),
    "xyzt_units": (0, 1, 3, 255), "magic": (b"n+1\x00", b"ni1\x00", b"n+2\x00", b"\x00\x00\x00\x00"),
    "dim_info": (255,), "slice_end": (-1, 32767), "cal_max": (float("nan"),),
}


def nifti_field(rng: random.Random, data: bytes, ctx):
    from nibabel.nifti1 import header_dtype

    gz = data[:2] == b"\x1f\x8b"
    try:
        raw = bytearray(gzip.decompress(data) if gz else data)
    except (OSError, EOFError):
        return bit_flips(rng, data, ctx)
    if len(raw) < header_dtype.itemsize:
        return bit_flips(rng, data, ctx)
    swap = int.from_bytes(raw[:4], "little") != 348
    name = rng.choice(list(_NIFTI_VALUES))
    ftype, offset = header_dtype.fields[name][:2]
    base, shape = ftype.base, ftype.shape or (1,)
    if swap and base.itemsize > 1:
        base = base.newbyteorder(">")
    value = rng.choice(_NIFTI_VALUES[name])
    index = rng.randrange(int(np.prod(shape)))
    if isinstance(value, bytes):
        raw[offset:offset + len(value)] = value
    else:
        with np.errstate(over="ignore", invalid="ignore"):
            cast = np.array(value).astype(base)
        at = offset + index * base.itemsize
        raw[at:at + base.itemsize] = cast.tobytes()
    out = bytes(raw)
    return (gzip.compress(out, mtime=0) if gz else out), f"NIfTI {name}[{index}] = {value!r}"


_NPY_SHAPES = ("(100000, 100000, 100000)", "(-1, 6, 5)", "()", "(0,)", "(5,)", "(1,) * 3", "(5, 6, 7, 8)",
               "(" * 3000 + ")" * 3000, "(2**70, 1, 1)", "(5.5, 6, 7)", "'abc'", "(5, 6, 7)", "(" + "1," * 40 + ")")
_NPY_DESCRS = ("'<f8'", "'|O'", "'<U10'", "'|V8'", "'<c16'", "'garbage'", "[('a', '<i4')]", "'>i2'", "'<M8[s]'",
               "'<i2'", "'|b1'", "'" + "<i2" * 2000 + "'", "[" * 2000 + "]" * 2000)


def _npy_edit(rng: random.Random, data: bytes) -> tuple[bytes, str]:
    if not data.startswith(b"\x93NUMPY") or len(data) < 10:
        return data, "not npy"
    major = data[6]
    size_len = 2 if major == 1 else 4
    hlen = int.from_bytes(data[8:8 + size_len], "little")
    start = 8 + size_len
    header, body = data[start:start + hlen].decode("latin-1"), data[start + hlen:]
    what = rng.choice(("shape", "descr", "fortran", "length", "version", "dict"))
    if what == "shape":
        value = rng.choice(_NPY_SHAPES)
        header = _replace_entry(header, "shape", value)
    elif what == "descr":
        value = rng.choice(_NPY_DESCRS)
        header = _replace_entry(header, "descr", value)
    elif what == "fortran":
        value = rng.choice(("True", "1", "'x'", "None"))
        header = _replace_entry(header, "fortran_order", value)
    elif what == "dict":
        value = rng.choice(("{}", "[]", "{'descr': '<i2'}", "{" * 3000, "1 +", "__import__('os')", "{'a': 1} {}"))
        header = value
    elif what == "length":
        value = rng.choice((0, 1, 65535, 2**31 - 1, len(header) + 5, len(header) - 5))
        size = value.to_bytes(size_len, "little", signed=False) if value < 256 ** size_len else b"\xff" * size_len
        return data[:8] + size + data[start:], f"npy header length {value}"
    else:
        value = rng.choice((0, 2, 3, 9))
        return data[:6] + bytes([value]) + data[7:], f"npy version {value}"
    head = header.encode("latin-1")
    size = len(head).to_bytes(size_len, "little") if len(head) < 256 ** size_len else b"\xff" * size_len
    return data[:8] + size + head + body, f"npy {what} = {value[:60]!r}"


def _replace_entry(header: str, key: str, value: str) -> str:
    i = header.find(f"'{key}':")
    if i < 0:
        return header
    j = i + len(key) + 3
    depth, k = 0, j
    while k < len(header):
        c = header[k]
        depth += c in "([{"
        depth -= c in ")]}"
        if depth <= 0 and c in ",}" and k > j:
            break
        k += 1
    return header[:j] + " " + value + header[k:]


def npy_field(rng, data, ctx):
    return _npy_edit(rng, data)


def npz_member(rng, data, ctx):
    """Rewrite one member of the archive with an edited ``.npy`` header (or bit flips)."""
    try:
        with zipfile.ZipFile(io.BytesIO(data)) as z:
            members = {n: z.read(n) for n in z.namelist()}
    except (zipfile.BadZipFile, OSError, ValueError, EOFError):
        return bit_flips(rng, data, ctx)
    name = rng.choice(sorted(members))
    if rng.random() < 0.7:
        members[name], what = _npy_edit(rng, members[name])
    else:
        members[name], what = bit_flips(rng, members[name], ctx)
    if rng.random() < 0.1:
        members[rng.choice(("data.npy", "spacing.npy", "affine.npy"))] = members.pop(name)
        what += ", renamed"
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", rng.choice((zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED))) as z:
        for n, b in members.items():
            z.writestr(n, b)
    return buf.getvalue(), f"npz {name}: {what}"


_DICOM_TAGS = ("Rows", "Columns", "BitsAllocated", "BitsStored", "HighBit", "PixelRepresentation",
               "SamplesPerPixel", "PhotometricInterpretation", "NumberOfFrames", "PixelData", "PixelSpacing",
               "ImageOrientationPatient", "ImagePositionPatient", "SliceThickness", "RescaleSlope",
               "RescaleIntercept", "SOPClassUID", "SeriesInstanceUID", "Modality", "PlanarConfiguration",
               "SpacingBetweenSlices", "WindowCenter", "LargestImagePixelValue", "TransferSyntaxUID")
_DICOM_VALUES = {
    "Rows": (0, 1, 65535), "Columns": (0, 1, 65535), "BitsAllocated": (0, 1, 7, 12, 32, 64, 65535),
    "BitsStored": (0, 1, 17, 64), "HighBit": (0, 63, 65535), "PixelRepresentation": (0, 1, 2),
    "SamplesPerPixel": (0, 2, 3, 4, 65535),
    "PhotometricInterpretation": ("RGB", "PALETTE COLOR", "YBR_FULL", "FOO", ""),
    "NumberOfFrames": ("0", "-1", "2", "100000000", "abc"), "PixelSpacing": (["0", "0"], ["-1", "1"], ["nan", "1"],
                                                                              ["1e308", "1e308"], ["1"]),
    "ImageOrientationPatient": (["0"] * 6, ["1", "0", "0", "1", "0", "0"], ["nan"] * 6, ["1", "0"]),
    "ImagePositionPatient": (["nan", "0", "0"], ["1e308", "0", "0"], ["1"]), "SliceThickness": ("0", "-1", "nan"),
    "RescaleSlope": ("0", "inf", "nan", "1e308", "-1e308"), "RescaleIntercept": ("inf", "1e308", "nan"),
    "PlanarConfiguration": (0, 1, 2), "SpacingBetweenSlices": ("0", "-5", "nan"),
    "TransferSyntaxUID": ("1.2.840.10008.1.2.1.99", "1.2.840.10008.1.2.4.50", "1.2.840.10008.1.2.5",
                          "1.2.840.10008.1.2.1.99", "1.2.840.10008.1.2.2", "1.2.840.10008.1.2", "garbage"),
}


def dicom_field(rng: random.Random, data: bytes, ctx, *, others: tuple[bytes, ...] = ()):
    import logging
    import warnings

    import pydicom

    log = logging.getLogger("pydicom")
    was = log.disabled
    log.disabled = True  # pydicom logs every odd value the mutation writes
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return _dicom_edit(pydicom, rng, data, ctx, others)
    finally:
        log.disabled = was


def _dicom_edit(pydicom, rng, data, ctx, others):
    try:
        ds = pydicom.dcmread(io.BytesIO(data), force=True)
        ds.file_meta  # noqa: B018  (parses the meta group now, inside the try)
        tag = rng.choice(_DICOM_TAGS)
        target = ds.file_meta if tag == "TransferSyntaxUID" else ds
        how = rng.choice(("delete", "empty", "set", "set", "mix"))
        if how == "delete" and tag in target:
            delattr(target, tag)
        elif how == "empty" and tag in target:
            target[tag].value = None
        elif how == "mix" and others:
            donor = pydicom.dcmread(io.BytesIO(rng.choice(others)), force=True)
            if tag in donor:
                target[tag] = donor[tag]
        elif tag in _DICOM_VALUES:
            setattr(target, tag, rng.choice(_DICOM_VALUES[tag]))
        buf = io.BytesIO()
        ds.save_as(buf, enforce_file_format=False)
        return buf.getvalue(), f"DICOM {how} {tag}"
    except Exception:  # noqa: BLE001  (a seed pydicom cannot rewrite still gets a mutation)
        return bit_flips(rng, data, ctx)


def raw_options(rng: random.Random, options: dict) -> tuple[dict, str]:
    """Edit one option of a raw file's loader arguments."""
    out = dict(options)
    key = rng.choice(("shape", "dtype", "offset", "byte_order", "spacing"))
    out[key] = rng.choice({
        "shape": ([100000, 100000, 100000], [-1, 6, 7], [0, 6, 7], [5, 6], [2**62, 2, 2], [5, 6, 7, 1]),
        "dtype": ("float64", "O", "U5", "V3", "foo", "complex64", "uint8", "int64"),
        "offset": (-1, 10**12, 3, 2**63, 1),
        "byte_order": ("middle", "big", "<"),
        "spacing": ([0, 1, 1], [-1, 1, 1], ["nan", 1, 1], [1, 1]),
    }[key])
    if key == "spacing" and "nan" in out[key]:
        out[key] = [float("nan"), 1, 1]
    return out, f"raw option {key} = {str(out[key])[:40]}"
