"""Bad input gets a typed error naming the file, never a bare nibabel/ITK/numpy exception."""

from __future__ import annotations

import gzip
import zlib

import nibabel as nib
import numpy as np
import pytest

import volumen
from volumen.core import Volume
from volumen.errors import (
    CorruptDataError,
    DataSizeError,
    MissingPathError,
    NonFiniteValuesError,
    UnknownFormatError,
    VolumeReadError,
    VolumeWriteError,
)

SHAPE = (7, 9, 11)  # (nz, ny, nx)


def small_volume(dtype=np.int16) -> Volume:
    data = np.arange(np.prod(SHAPE)).reshape(SHAPE).astype(dtype)
    return Volume(data, spacing=(2.5, 0.7, 1.3))


def raises(exc_type, path, **options):
    """Load ``path`` expecting ``exc_type``; the message must name the file."""
    with pytest.raises(exc_type) as info:
        volumen.load(path, **options)
    assert path.name in str(info.value)
    assert isinstance(info.value, VolumeReadError)
    return info.value


def test_missing_path(tmp_path):
    raises(MissingPathError, tmp_path / "nowhere.nii")


def test_unknown_format(tmp_path):
    path = tmp_path / "scan.xyz"
    path.write_bytes(b"hello")
    raises(UnknownFormatError, path)


# -- raw --------------------------------------------------------------------------------
def test_raw_too_short_and_too_long(tmp_path):
    path = tmp_path / "v.raw"
    path.write_bytes(bytes(2 * np.prod(SHAPE) - 2))
    err = raises(DataSizeError, path, shape=SHAPE, dtype="int16")
    assert "1386 bytes" in str(err) and "1384" in str(err)
    path.write_bytes(bytes(2 * np.prod(SHAPE) + 10))
    err = raises(DataSizeError, path, shape=SHAPE, dtype="int16")
    assert "allow_trailing" in str(err) and "1396" in str(err)
    vol = volumen.load(path, shape=SHAPE, dtype="int16", allow_trailing=True)
    assert vol.shape == SHAPE
    vol = volumen.load(path, shape=SHAPE, dtype="int16", offset=10)
    assert vol.shape == SHAPE


def test_raw_needs_shape_and_dtype(tmp_path):
    path = tmp_path / "v.raw"
    path.write_bytes(bytes(100))
    err = raises(VolumeReadError, path, dtype="uint8")
    assert "shape" in str(err) and "dtype" not in str(err).split(":")[1].split("(")[0]
    err = raises(VolumeReadError, path)
    assert "shape and dtype" in str(err)
    raises(VolumeReadError, path, shape=(1, 10, 10), dtype="uint8", byte_order="middle")


# -- garbage and empty files with a known suffix -----------------------------------------
KNOWN = [".nii", ".nii.gz", ".nrrd", ".nhdr", ".mha", ".mhd", ".vtk", ".npy", ".npz"]


@pytest.mark.parametrize("suffix", KNOWN)
@pytest.mark.parametrize("content", ["random", "empty"])
def test_garbage_with_known_suffix(tmp_path, suffix, content):
    path = tmp_path / f"junk{suffix}"
    path.write_bytes(np.random.default_rng(0).bytes(4096) if content == "random" else b"")
    raises(CorruptDataError, path)


# -- NIfTI ----------------------------------------------------------------------------------
def test_nifti_truncated(tmp_path):
    path = tmp_path / "t.nii"
    volumen.save(small_volume(), path)
    path.write_bytes(path.read_bytes()[:-100])
    err = raises(DataSizeError, path)
    assert "too short" in str(err)


def test_nifti_corrupt_gzip(tmp_path):
    path = tmp_path / "c.nii.gz"
    volumen.save(small_volume(np.float32), path)
    blob = bytearray(path.read_bytes())
    blob[len(blob) // 2:len(blob) // 2 + 40] = np.random.default_rng(1).bytes(40)
    path.write_bytes(bytes(blob))
    raises(CorruptDataError, path)
    path.write_bytes(path.read_bytes()[: len(blob) // 2])  # cut short
    raises(CorruptDataError, path)


@pytest.mark.parametrize("policy", ["zero", "min", "error", "keep"])
def test_nifti_nonfinite_policies(tmp_path, policy):
    data = np.linspace(-5, 5, np.prod(SHAPE), dtype=np.float32).reshape(SHAPE)
    data[1, 2, 3], data[4, 5, 6], data[6, 8, 10] = np.nan, np.inf, -np.inf
    path = tmp_path / "nan.nii"
    nib.save(nib.Nifti1Image(data.transpose(2, 1, 0), np.eye(4)), path)
    if policy == "error":
        err = raises(NonFiniteValuesError, path, nonfinite="error")
        assert "3 of 693" in str(err)
        return
    vol = volumen.load(path) if policy == "zero" else volumen.load(path, nonfinite=policy)
    bad = (1, 2, 3), (4, 5, 6), (6, 8, 10)
    mask = np.ones(SHAPE, bool)
    for b in bad:
        mask[b] = False
    assert np.array_equal(vol.data[mask], data[mask])
    assert any("3 of 693" in w for w in vol.meta["warnings"])
    if policy == "keep":
        assert np.isnan(vol.data[bad[0]]) and vol.data[bad[1]] == np.inf and vol.data[bad[2]] == -np.inf
    else:
        fill = 0.0 if policy == "zero" else float(np.nanmin(data[mask]))
        assert fill == (0.0 if policy == "zero" else -5.0)
        assert all(vol.data[b] == fill for b in bad)


# -- NRRD -----------------------------------------------------------------------------------
def _nhdr(path, data_file, enc="raw"):
    path.write_text("NRRD0004\ntype: short\ndimension: 3\nsizes: 11 9 7\nspace: RAS\n"
                    "space directions: (1,0,0) (0,1,0) (0,0,1)\n"
                    f"endian: little\nencoding: {enc}\ndata file: {data_file}")


def test_nrrd_attached_truncated(tmp_path):
    path = tmp_path / "t.nrrd"
    volumen.save(small_volume(), path)
    path.write_bytes(path.read_bytes()[:-7])
    err = raises(DataSizeError, path)
    assert "1386 bytes" in str(err) and "1379" in str(err)


def test_nhdr_detached_too_short_and_missing(tmp_path):
    (tmp_path / "d.raw").write_bytes(bytes(1000))
    _nhdr(tmp_path / "d.nhdr", "d.raw\n")
    err = raises(DataSizeError, tmp_path / "d.nhdr")
    assert "d.raw" in str(err) and "1386" in str(err)
    _nhdr(tmp_path / "m.nhdr", "missing.raw\n")
    err = raises(MissingPathError, tmp_path / "m.nhdr")
    assert "missing.raw" in str(err)


def test_nhdr_list_forms_broken(tmp_path):
    for k in range(1, 7):  # slice 7 of 7 is missing
        (tmp_path / f"s{k}.raw").write_bytes(bytes(2 * 99))
    _nhdr(tmp_path / "p.nhdr", "s%d.raw 1 7 1\n")
    assert "s7.raw" in str(raises(MissingPathError, tmp_path / "p.nhdr"))
    (tmp_path / "s7.raw").write_bytes(bytes(2 * 50))  # short slice
    assert "s7.raw" in str(raises(DataSizeError, tmp_path / "p.nhdr"))
    _nhdr(tmp_path / "l.nhdr", "LIST 3\ns1.raw\ns2.raw\n")  # slabs add up to 2 of 7 slices
    raises(DataSizeError, tmp_path / "l.nhdr")


def test_nrrd_corrupt_gzip(tmp_path):
    path = tmp_path / "g.nrrd"
    path.write_bytes(b"NRRD0004\ntype: short\ndimension: 3\nsizes: 11 9 7\nencoding: gzip\n\n"
                     + np.random.default_rng(2).bytes(500))
    raises(CorruptDataError, path)
    good = gzip.compress(bytes(2 * np.prod(SHAPE)))
    path.write_bytes(path.read_bytes().split(b"\n\n")[0] + b"\n\n" + good[: len(good) // 2])
    raises(CorruptDataError, path)


def test_nrrd_broken_header(tmp_path):
    path = tmp_path / "h.nrrd"
    path.write_bytes(b"NRRD0004\ntype: quaternion\ndimension: 3\nsizes: 11 9 7\nencoding: raw\n\n" + bytes(10))
    raises(CorruptDataError, path)
    path.write_bytes(b"NRRD0004\ntype: short\ndimension: 3\nsizes: 11 9\nencoding: raw\n\n" + bytes(10))
    raises(CorruptDataError, path)


# -- MetaImage ---------------------------------------------------------------------------------
def test_mha_truncated(tmp_path):
    path = tmp_path / "t.mha"
    volumen.save(small_volume(), path)
    path.write_bytes(path.read_bytes()[:-100])
    err = raises(DataSizeError, path)
    assert "1386 bytes" in str(err)


def test_mhd_detached_too_short_and_missing(tmp_path):
    path = tmp_path / "d.mhd"
    volumen.save(small_volume(), path)
    raw = tmp_path / "d.raw"
    raw.write_bytes(raw.read_bytes()[:500])
    err = raises(DataSizeError, path)
    assert "d.raw" in str(err) and "500" in str(err)
    raw.unlink()
    assert "d.raw" in str(raises(MissingPathError, path))


def test_mhd_corrupt_zraw(tmp_path):
    path = tmp_path / "z.mhd"
    (tmp_path / "z.zraw").write_bytes(np.random.default_rng(3).bytes(300))
    path.write_text("ObjectType = Image\nNDims = 3\nBinaryData = True\nCompressedData = True\n"
                    "CompressedDataSize = 300\nDimSize = 11 9 7\nElementType = MET_SHORT\n"
                    "ElementDataFile = z.zraw\n")
    raises(CorruptDataError, path)
    (tmp_path / "z.zraw").write_bytes(zlib.compress(bytes(100)))  # valid zlib, too little data
    assert "inflates to 100 bytes" in str(raises(DataSizeError, path))
    (tmp_path / "z.zraw").write_bytes(zlib.compress(bytes(1386))[:-20])  # cut short
    raises(DataSizeError, path)


# -- VTK ---------------------------------------------------------------------------------------
VTK_HEAD = ("# vtk DataFile Version 3.0\nt\n{mode}\nDATASET STRUCTURED_POINTS\nDIMENSIONS 11 9 7\n"
            "SPACING 1 1 1\nORIGIN 0 0 0\nPOINT_DATA 693\nSCALARS v short 1\nLOOKUP_TABLE default\n")


def test_vtk_binary_too_short(tmp_path):
    path = tmp_path / "b.vtk"
    path.write_bytes(VTK_HEAD.format(mode="BINARY").encode() + bytes(1000))
    err = raises(DataSizeError, path)
    assert "1386 bytes" in str(err) and "1000" in str(err)


def test_vtk_ascii_too_short_and_not_numbers(tmp_path):
    path = tmp_path / "a.vtk"
    path.write_text(VTK_HEAD.format(mode="ASCII") + " ".join(["1"] * 600))
    assert "600" in str(raises(DataSizeError, path))
    path.write_text(VTK_HEAD.format(mode="ASCII") + " ".join(["x"] * 693))
    raises(CorruptDataError, path)


def test_vtk_other_dataset_and_bad_header(tmp_path):
    path = tmp_path / "p.vtk"
    path.write_text("# vtk DataFile Version 3.0\nmesh\nASCII\nDATASET POLYDATA\nPOINTS 0 float\n")
    raises(UnknownFormatError, path)
    path.write_text(VTK_HEAD.format(mode="ASCII").replace("POINT_DATA 693", "POINT_DATA 700"))
    raises(CorruptDataError, path)
    path.write_text(VTK_HEAD.format(mode="ASCII").replace("short", "quaternion"))
    raises(CorruptDataError, path)


# -- NumPy ---------------------------------------------------------------------------------------
def test_npz_without_the_key(tmp_path):
    path = tmp_path / "k.npz"
    np.savez(path, a=np.zeros(SHAPE), b=np.zeros(SHAPE))
    err = raises(VolumeReadError, path)
    assert "'a'" in str(err) and "key=" in str(err)


def test_npy_wrong_dimensions(tmp_path):
    path = tmp_path / "d.npy"
    np.save(path, np.zeros((2, 3, 4, 5)))
    raises(CorruptDataError, path)


def test_save_unknown_suffix(tmp_path):
    with pytest.raises(VolumeWriteError) as info:
        volumen.save(small_volume(), tmp_path / "v.vtk")
    assert "v.vtk" in str(info.value)


def test_unknown_reader_option_is_a_read_error(tmp_path):
    """An option the format's reader does not take names the reader's real options."""
    import numpy as np

    import volumen
    from volumen.errors import VolumeReadError

    volumen.save(volumen.Volume(np.zeros((2, 3, 4), np.uint8)), tmp_path / "v.nrrd")
    with pytest.raises(VolumeReadError, match="does not take option"):
        volumen.load(tmp_path / "v.nrrd", series="1.2.3")
