"""Each crash, hang, out-of-memory, untyped error and outside read the fuzzer found, as its minimal mutant.

The files are a few lines of header written here. Unchecked, such a header crashes
SimpleITK (SIGSEGV/SIGABRT/SIGFPE), hangs (``line skip``, a 10^8-file pattern), asks
numpy for petabytes, raises TokenError/KeyError/IndexError/IsADirectoryError, or reads
files outside the header's folder; each must raise a typed error naming the file.
"""

from __future__ import annotations

import gzip
import io
import zipfile

import nibabel as nib
import numpy as np
import pytest

import volumen
from volumen.errors import (
    CorruptDataError,
    DataSizeError,
    OutsideFolderError,
    UnexpectedReadError,
    VolumeReadError,
)

SLICE = np.arange(6 * 7, dtype="<i2").reshape(6, 7)
NRRD = "NRRD0004\ntype: short\ndimension: 3\nsizes: 7 6 2\nendian: little\nencoding: raw\n"
MHD = "ObjectType = Image\nNDims = 3\nDimSize = 7 6 2\nElementType = MET_SHORT\n"


def typed(exc_type, path, **options):
    with pytest.raises(exc_type) as info:
        volumen.load(path, **options)
    assert isinstance(info.value, VolumeReadError) and not isinstance(info.value, UnexpectedReadError)
    assert path.name in str(info.value)
    return str(info.value)


def write(folder, name, text: str, data: bytes = b"") -> object:
    path = folder / name
    path.write_bytes(text.encode("latin-1") + data)
    return path


# -- hangs -----------------------------------------------------------------------------------
def test_nrrd_huge_line_skip_fails_fast(tmp_path):
    path = write(tmp_path, "l.nrrd", NRRD + "line skip: 100000000\n\n", SLICE.tobytes() * 2)
    assert "line skip" in typed(DataSizeError, path)


def test_nrrd_pattern_with_huge_range_is_refused_before_expanding(tmp_path):
    path = write(tmp_path, "p.nhdr", NRRD + "data file: x%03d.raw 0 100000000 1\n")
    assert "100000001 files" in typed(DataSizeError, path)


# -- process crashes inside SimpleITK's reader (now parsed in Python) ---------------------------
@pytest.mark.parametrize("ndims", ["-1", "100", "99999999999999999999", "0"])
def test_metaimage_bad_ndims(tmp_path, ndims):
    path = write(tmp_path, "n.mha", MHD.replace("NDims = 3", f"NDims = {ndims}") + "ElementDataFile = LOCAL\n",
                 SLICE.tobytes() * 2)
    assert "NDims" in typed(CorruptDataError, path)


def test_metaimage_pattern_with_zero_step(tmp_path):
    path = write(tmp_path, "p.mhd", MHD + "ElementDataFile = %d 1 3 0\n")
    assert "step 0" in typed(CorruptDataError, path)


@pytest.mark.parametrize("name", [".", "", ".."])
def test_metaimage_data_file_is_a_folder(tmp_path, name):
    (tmp_path / "sub").mkdir()
    path = write(tmp_path / "sub", "d.mhd", MHD + f"ElementDataFile = {name}\n")
    typed(VolumeReadError, path)


# -- data files outside the header's folder ---------------------------------------------------
@pytest.mark.parametrize("kind", ["nrrd", "mhd"])
def test_data_file_outside_folder_needs_allow_outside(tmp_path, kind):
    (tmp_path / "data.raw").write_bytes(SLICE.tobytes() * 2)
    (tmp_path / "h").mkdir()
    for target in ("../data.raw", str(tmp_path / "data.raw")):
        head = NRRD + f"data file: {target}\n" if kind == "nrrd" else MHD + f"ElementDataFile = {target}\n"
        path = write(tmp_path / "h", f"v.{'nhdr' if kind == 'nrrd' else 'mhd'}", head)
        assert "allow_outside=True" in typed(OutsideFolderError, path)
        vol = volumen.load(path, allow_outside=True)
        assert np.array_equal(vol.data, np.stack([SLICE, SLICE]))


def test_nrrd_printf_conversions_other_than_d_are_refused(tmp_path):
    path = write(tmp_path, "n.nhdr", NRRD + "data file: %n%n%n 1 2 1\n")
    assert "%03d" in typed(CorruptDataError, path)


# -- untyped errors ---------------------------------------------------------------------------------
def test_nrrd_fewer_space_directions_than_axes(tmp_path):
    path = write(tmp_path, "d.nrrd", NRRD + "space: RAS\nspace directions: (1,0,0) (0,1,0)\n\n", SLICE.tobytes() * 2)
    typed(CorruptDataError, path)


def test_nrrd_byte_skip_too_large_for_an_offset(tmp_path):
    path = write(tmp_path, "b.nrrd", NRRD + "byte skip: 99999999999999999999\n\n", SLICE.tobytes() * 2)
    assert "byte skip" in typed(CorruptDataError, path)


@pytest.mark.parametrize("header", [
    "{'descr': '<i2', 'fortran_order': False, 'shape': (" + "(" * 3000,  # TokenError / RecursionError before
    "{'descr': '<i2', 'fortran_order': False, 'shape': (2, 6, 7), }" + "{" * 10,
    "{'descr': '|O', 'fortran_order': False, 'shape': (2, 6, 7), }",
    "{'descr': [('a', '<i2')], 'fortran_order': False, 'shape': (2, 6, 7), }",
])
def test_npy_broken_headers(tmp_path, header):
    head = header.encode("latin-1")
    path = tmp_path / "h.npy"
    path.write_bytes(b"\x93NUMPY\x01\x00" + len(head).to_bytes(2, "little") + head + SLICE.tobytes() * 2)
    typed(CorruptDataError, path)


def test_npy_huge_shape_is_refused_before_allocating(tmp_path):
    head = b"{'descr': '<i2', 'fortran_order': False, 'shape': (100000, 100000, 100000), }"
    path = tmp_path / "big.npy"
    path.write_bytes(b"\x93NUMPY\x01\x00" + len(head).to_bytes(2, "little") + head + SLICE.tobytes())
    assert "2000000000000000 bytes" in typed(DataSizeError, path)


def test_npz_bad_members(tmp_path):
    def npz(**members):
        buf = io.BytesIO()
        with zipfile.ZipFile(buf, "w") as z:
            for name, data in members.items():
                z.writestr(name + ".npy", data)
        path = tmp_path / "m.npz"
        path.write_bytes(buf.getvalue())
        return path

    def npy(a):
        buf = io.BytesIO()
        np.save(buf, a)
        return buf.getvalue()

    data = npy(np.stack([SLICE, SLICE]))
    typed(CorruptDataError, npz(data=data, spacing=npy(np.ones(2))))  # IndexError before
    bad_text = npy(np.array("CT"))[:-8] + b"\xff\xff\xff\x7f" * 2  # not a code point: SystemError before
    assert volumen.load(npz(data=data, name=bad_text)).name  # loads; the name is replaced characters
    typed(CorruptDataError, npz(data=data[:10] + b"\xff\xff" + data[12:]))  # header length past the end


def _nifti(tmp_path, **fields):
    img = nib.Nifti1Image(np.zeros((4, 3, 2), np.int16), np.eye(4))
    img.set_qform(np.eye(4), code=1)
    img.set_sform(np.eye(4), code=1)
    raw = bytearray(img.header.binaryblock)
    for name, value in fields.items():
        ftype, offset = nib.nifti1.header_dtype.fields[name][:2]
        raw[offset:offset + ftype.itemsize] = np.array(value).astype(ftype.base).tobytes()
    path = tmp_path / "q.nii.gz"
    path.write_bytes(gzip.compress(bytes(raw) + b"\x00" * 4 + bytes(48)))
    return path


def test_nifti_bad_quaternion_and_units(tmp_path):
    assert "header transform" in typed(CorruptDataError, _nifti(tmp_path, quatern_b=2.0))
    typed(CorruptDataError, _nifti(tmp_path, xyzt_units=255))


@pytest.mark.parametrize("line,value", [("ORIGIN 0 0 0", "ORIGIN nan 0 0"), ("SPACING 1 1 1", "SPACING inf 1 1"),
                                        ("SCALARS v short 1", "SCALARS v short 0"),
                                        ("SCALARS v short 1", "SCALARS v short 99999999999999999999"),
                                        ("POINT_DATA 84", "POINT_DATA 210000000000000000000000")])
def test_vtk_bad_header_numbers(tmp_path, line, value):
    head = ("# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 7 6 2\nSPACING 1 1 1\n"
            "ORIGIN 0 0 0\nPOINT_DATA 84\nSCALARS v short 1\nLOOKUP_TABLE default\n")
    path = write(tmp_path, "v.vtk", head.replace(line, value) + " ".join(map(str, range(84))))
    typed(CorruptDataError, path)


def test_the_load_net_types_what_no_check_anticipated(tmp_path, monkeypatch):
    from volumen.io import _vtk

    def broken(path):
        raise KeyError("surprise")

    monkeypatch.setattr(_vtk, "read", broken)
    path = write(tmp_path, "n.vtk", "# vtk DataFile Version 3.0\n")
    with pytest.raises(UnexpectedReadError) as info:
        volumen.load(path)
    assert "n.vtk" in str(info.value) and "KeyError" in str(info.value)
    assert isinstance(info.value, CorruptDataError)


def test_open_bounded_never_asks_for_more_than_the_file_holds(tmp_path):
    """A damaged DICOM length field made pydicom call read(~4 GB): MemoryError under a 4 GiB limit."""
    import pydicom
    from pydicom.data import get_testdata_file

    from volumen.io._header_limits import open_bounded

    path = tmp_path / "f.bin"
    path.write_bytes(b"0123456789")
    with open_bounded(path) as f:
        f.seek(4)
        assert f.read(1 << 62) == b"456789" and f.read(5) == b"" and f.tell() == 10
    src = get_testdata_file("CT_small.dcm")
    with open_bounded(src) as f:
        ds = pydicom.dcmread(f)
    assert np.array_equal(ds.pixel_array, pydicom.dcmread(src).pixel_array)


def test_the_load_net_also_catches_native_panics(tmp_path, monkeypatch):
    """pylibjpeg-rle's Rust decoder panics on a bit-flipped RLE stream: pyo3 raises a BaseException."""
    from volumen.io import _vtk

    class PanicException(BaseException):  # what pyo3 raises; not an Exception
        pass

    def panics(path):
        raise PanicException("index out of bounds: the len is 400 but the index is 402")

    monkeypatch.setattr(_vtk, "read", panics)
    path = write(tmp_path, "p.vtk", "# vtk DataFile Version 3.0\n")
    with pytest.raises(UnexpectedReadError, match="PanicException"):
        volumen.load(path)
