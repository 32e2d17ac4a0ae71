"""Round trips and geometry of the file formats, checked against nibabel, pynrrd and SimpleITK.

Volumes are 7 x 9 x 11 ([z, y, x], every axis a different size so a transpose
shows) with oblique affines and a different spacing on each axis.
"""

from __future__ import annotations

import gzip
import json
import zlib

import nibabel as nib
import nrrd
import numpy as np
import pytest
import SimpleITK as sitk

import volumen
from volumen.core import Volume

SHAPE = (7, 9, 11)  # (nz, ny, nx)
SPACING = (2.5, 0.7, 1.3)  # (dz, dy, dx) mm
LPS = np.diag([-1.0, -1.0, 1.0])
IJK = np.array([[0, 0, 0], [10, 8, 6], [3, 5, 2], [10, 0, 6]])  # (i, j, k) = (column, row, slice)


def rotation(a: float, b: float, c: float) -> np.ndarray:
    """A proper rotation from three angles in radians (z, then y, then x)."""
    ca, sa, cb, sb, cc, sc = np.cos(a), np.sin(a), np.cos(b), np.sin(b), np.cos(c), np.sin(c)
    rz = np.array([[ca, -sa, 0], [sa, ca, 0], [0, 0, 1]])
    ry = np.array([[cb, 0, sb], [0, 1, 0], [-sb, 0, cb]])
    rx = np.array([[1, 0, 0], [0, cc, -sc], [0, sc, cc]])
    return rz @ ry @ rx


def oblique_affine(spacing=SPACING, angles=(0.31, -0.17, 0.52), origin=(-101.3, 37.25, 12.125)) -> np.ndarray:
    aff = np.eye(4)
    aff[:3, :3] = rotation(*angles) @ np.diag(spacing[::-1])
    aff[:3, 3] = origin
    return aff


def make_data(dtype) -> np.ndarray:
    rng = np.random.default_rng(7)
    if np.dtype(dtype) == np.uint8:
        return rng.integers(0, 256, SHAPE).astype(np.uint8)
    if np.dtype(dtype) == np.int16:
        return rng.integers(-1024, 3072, SHAPE).astype(np.int16)
    return rng.normal(0, 100, SHAPE).astype(dtype)


def make_volume(dtype=np.int16) -> Volume:
    return Volume(make_data(dtype), spacing=SPACING, affine=oblique_affine(), modality="CT", units="HU",
                  name="phantom")


WRITABLE = [".nii", ".nii.gz", ".nrrd", ".nhdr", ".mha", ".mhd", ".npy", ".npz"]


@pytest.mark.parametrize("dtype", [np.int16, np.uint8, np.float32])
@pytest.mark.parametrize("suffix", WRITABLE)
def test_round_trip_is_exact(tmp_path, suffix, dtype):
    vol = make_volume(dtype)
    path = tmp_path / f"vol{suffix}"
    volumen.save(vol, path)
    back = volumen.load(path)
    assert back.data.dtype == np.dtype(dtype)
    assert back.data.shape == SHAPE and back.data.flags.c_contiguous
    assert np.array_equal(back.data, vol.data)
    assert back.spacing == vol.spacing
    assert back.affine.dtype == np.float64 and np.array_equal(back.affine, vol.affine)
    assert (back.modality, back.units, back.name) == ("CT", "HU", "phantom")
    assert back.meta["warnings"] == []


def test_npy_without_sidecar_warns_and_uses_1mm(tmp_path):
    path = tmp_path / "bare.npy"
    np.save(path, make_data(np.int16))
    vol = volumen.load(path)
    assert np.array_equal(vol.data, make_data(np.int16))
    assert vol.spacing == (1.0, 1.0, 1.0) and np.array_equal(vol.affine, np.eye(4))
    assert any("geometry unknown" in w for w in vol.meta["warnings"])


def test_npz_key_option_and_spacing_only(tmp_path):
    path = tmp_path / "two.npz"
    np.savez(path, image=make_data(np.float32), spacing=np.array(SPACING))
    vol = volumen.load(path, key="image")
    assert np.array_equal(vol.data, make_data(np.float32))
    assert np.array_equal(vol.affine, np.diag([1.3, 0.7, 2.5, 1.0]))


# -- NIfTI against nibabel -------------------------------------------------------
def test_nifti_pair_hdr_img(tmp_path):
    vol = make_volume(np.float32)
    volumen.save(vol, tmp_path / "pair.img")
    assert (tmp_path / "pair.hdr").exists()
    for name in ("pair.hdr", "pair.img"):
        back = volumen.load(tmp_path / name)
        assert np.array_equal(back.data, vol.data) and np.array_equal(back.affine, vol.affine)
    img = nib.load(tmp_path / "pair.hdr")
    assert isinstance(img, nib.Nifti1Pair)
    assert np.array_equal(np.asanyarray(img.dataobj).transpose(2, 1, 0), vol.data)


def test_nifti_matches_nibabel(tmp_path):
    vol = make_volume(np.int16)
    path = tmp_path / "v.nii.gz"
    volumen.save(vol, path)
    img = nib.load(path)
    assert img.shape == SHAPE[::-1]  # NIfTI is [x, y, z]
    assert int(img.header["sform_code"]) == 1 and int(img.header["qform_code"]) == 1
    nib_world = nib.affines.apply_affine(img.affine, IJK)
    np.testing.assert_allclose(vol.index_to_world(IJK), nib_world, rtol=0, atol=1e-4)  # sform is float32
    np.testing.assert_allclose(img.get_qform(), vol.affine, rtol=0, atol=1e-4)
    arr = np.asanyarray(img.dataobj)
    for i, j, k in IJK:
        assert arr[i, j, k] == vol.data[k, j, i]
    assert np.array_equal(arr.transpose(2, 1, 0), vol.data)


def test_nifti_written_by_nibabel_qform_scaling(tmp_path):
    xyz = make_data(np.int16).transpose(2, 1, 0)
    aff = oblique_affine()
    img = nib.Nifti1Image(xyz, None)
    img.set_qform(aff, code=1)
    img.set_sform(np.eye(4), code=0)
    img.header.set_slope_inter(0.5, -10.25)
    path = tmp_path / "q.nii"
    nib.save(img, path)
    vol = volumen.load(path)
    assert vol.meta["nifti_xform"] == "qform"
    np.testing.assert_allclose(vol.affine, nib.load(path).affine, rtol=0, atol=1e-12)
    np.testing.assert_allclose(vol.affine, aff, rtol=0, atol=1e-4)
    assert vol.data.dtype == np.float32  # int16 storage, non-integer scaling
    np.testing.assert_array_equal(vol.data, (make_data(np.int16) * 0.5 - 10.25).astype(np.float32))


def test_nifti_integer_scaling_stays_integer(tmp_path):
    raw = np.random.default_rng(3).integers(0, 4000, SHAPE).astype(np.uint16)
    img = nib.Nifti1Image(raw.transpose(2, 1, 0), np.diag([0.5, 0.6, 2.0, 1.0]), dtype=np.uint16)
    img.header.set_slope_inter(1.0, -1024.0)
    path = tmp_path / "ct.nii"
    nib.save(img, path)
    vol = volumen.load(path)
    assert vol.meta["nifti_xform"] == "sform" and vol.data.dtype == np.int16
    assert np.array_equal(vol.data, raw.astype(np.int32) - 1024)
    np.testing.assert_allclose(vol.spacing, (2.0, 0.6, 0.5), rtol=2 ** -23)  # a float32 sform, no record


def test_nifti_4d_reads_first_volume(tmp_path):
    xyzt = np.random.default_rng(4).normal(size=SHAPE[::-1] + (3,)).astype(np.float32)
    path = tmp_path / "t.nii"
    nib.save(nib.Nifti1Image(xyzt, oblique_affine()), path)
    vol = volumen.load(path)
    assert np.array_equal(vol.data, xyzt[..., 0].transpose(2, 1, 0))
    assert any("first volume" in w for w in vol.meta["warnings"])


def test_nifti_record_ignored_when_sform_edited(tmp_path):
    path = tmp_path / "e.nii"
    volumen.save(make_volume(), path)
    img = nib.load(path)
    moved = img.affine.copy()
    moved[:3, 3] += [5.0, 0.0, 0.0]
    img.set_sform(moved, code=2)
    nib.save(nib.Nifti1Image(np.asanyarray(img.dataobj), None, img.header), path)
    vol = volumen.load(path)
    np.testing.assert_allclose(vol.affine, moved, rtol=0, atol=1e-12)
    assert any("disagrees with the sform" in w for w in vol.meta["warnings"])


# -- NRRD against pynrrd ------------------------------------------------------------
def test_nrrd_matches_pynrrd(tmp_path):
    vol = make_volume(np.float32)
    path = tmp_path / "v.nrrd"
    volumen.save(vol, path)
    data, hdr = nrrd.read(str(path), index_order="C")
    assert data.shape == SHAPE and np.array_equal(data, vol.data)
    assert hdr["space"] == "left-posterior-superior"
    assert np.array_equal(LPS @ np.asarray(hdr["space directions"]).T, vol.affine[:3, :3])
    assert np.array_equal(LPS @ np.asarray(hdr["space origin"]), vol.affine[:3, 3])


def test_nrrd_written_by_pynrrd_ras_gzip(tmp_path):
    aff = oblique_affine()
    data = make_data(np.int16)
    hdr = {"space": "right-anterior-superior", "space directions": aff[:3, :3].T, "space origin": aff[:3, 3],
           "kinds": ["domain"] * 3, "encoding": "gzip", "endian": "big"}
    path = tmp_path / "ras.nrrd"
    nrrd.write(str(path), data, hdr, index_order="C")
    vol = volumen.load(path)
    assert np.array_equal(vol.data, data) and vol.data.dtype == np.int16
    np.testing.assert_allclose(vol.affine, aff, rtol=0, atol=1e-12)
    np.testing.assert_allclose(vol.spacing, SPACING, rtol=1e-12)


def test_nrrd_vector_axis_and_scanner_xyz(tmp_path):
    data = np.random.default_rng(5).normal(size=SHAPE + (2,)).astype(np.float32)  # x fastest after components
    hdr = {"space": "scanner-xyz", "kinds": ["vector", "domain", "domain", "domain"],
           "space directions": np.array([[np.nan] * 3, [1.3, 0, 0], [0, 0.7, 0], [0, 0, 2.5]]),
           "space origin": [1.0, 2.0, 3.0]}
    path = tmp_path / "vec.nrrd"
    nrrd.write(str(path), data, hdr, index_order="C")
    vol = volumen.load(path)
    assert np.array_equal(vol.data, data[..., 0])
    assert np.array_equal(vol.affine, np.array([[-1.3, 0, 0, -1], [0, -0.7, 0, -2], [0, 0, 2.5, 3], [0, 0, 0, 1]]))
    assert len(vol.meta["warnings"]) == 2  # no patient frame; vector axis reduced


def test_nrrd_spacings_only_is_taken_as_lps(tmp_path):
    data = make_data(np.uint8)
    path = tmp_path / "s.nrrd"
    nrrd.write(str(path), data, {"spacings": [1.3, 0.7, 2.5], "axis mins": [4.0, 5.0, 6.0]}, index_order="C")
    vol = volumen.load(path)
    assert np.array_equal(vol.data, data) and vol.spacing == SPACING
    assert np.array_equal(vol.affine, np.array([[-1.3, 0, 0, -4], [0, -0.7, 0, -5], [0, 0, 2.5, 6], [0, 0, 0, 1]]))
    assert any("orientation unknown" in w for w in vol.meta["warnings"])


def test_nrrd_spacings_keep_sign_and_cell_centering(tmp_path):
    """A negative spacing is an axis running the other way; for a cell-centred axis 'axis mins' is the first
    cell's edge, so the first voxel centre lies half a spacing further."""
    data = make_data(np.uint8)
    path = tmp_path / "c.nrrd"
    nrrd.write(str(path), data, {"spacings": [1.3, -0.7, 2.5], "axis mins": [4.0, 5.0, 6.0],
                                 "centerings": ["cell", "node", "cell"]}, index_order="C")
    vol = volumen.load(path)
    # NRRD axes are (x, y, z) fastest first: x cell (+0.65), y node, z cell (+1.25); LPS -> RAS flips x and y
    expected = np.array([[-1.3, 0, 0, -(4 + 0.65)], [0, 0.7, 0, -5], [0, 0, 2.5, 6 + 1.25], [0, 0, 0, 1]])
    np.testing.assert_allclose(vol.affine, expected, atol=1e-12)


def _nhdr(path, data_file: str, enc="raw", endian="little", extra="") -> None:
    path.write_text(
        "NRRD0004\n# written by the test\ntype: short\ndimension: 3\n"
        "space: left-posterior-superior\nsizes: 11 9 7\n"
        "space directions: (1.3,0,0) (0,0.7,0) (0,0,2.5)\nspace origin: (10,-20,30)\n"
        f"kinds: domain domain domain\nendian: {endian}\nencoding: {enc}\n{extra}data file: {data_file}")


EXPECTED_NHDR = np.array([[-1.3, 0, 0, -10], [0, -0.7, 0, 20], [0, 0, 2.5, 30], [0, 0, 0, 1]])


@pytest.mark.parametrize("endian", ["little", "big"])
def test_nhdr_detached_raw(tmp_path, endian):
    data = make_data(np.int16)
    (tmp_path / "d.raw").write_bytes(data.astype("<i2" if endian == "little" else ">i2").tobytes())
    _nhdr(tmp_path / "d.nhdr", "d.raw\n", endian=endian)
    vol = volumen.load(tmp_path / "d.nhdr")
    assert np.array_equal(vol.data, data) and vol.data.dtype.isnative
    assert np.array_equal(vol.affine, EXPECTED_NHDR)


def test_nhdr_pattern_list_form(tmp_path):
    data = make_data(np.int16)
    for k in range(SHAPE[0]):  # slices 1..7, gzip, each behind a 4-byte skip of the decompressed data
        (tmp_path / f"slice{k + 1:03d}.raw.gz").write_bytes(gzip.compress(b"SKIP" + data[k].tobytes()))
    _nhdr(tmp_path / "p.nhdr", "slice%03d.raw.gz 1 7 1 2\n", enc="gzip", extra="byte skip: 4\n")
    vol = volumen.load(tmp_path / "p.nhdr")
    assert np.array_equal(vol.data, data)
    assert np.array_equal(vol.affine, EXPECTED_NHDR)


def test_nhdr_LIST_form_with_slabs(tmp_path):
    data = make_data(np.int16)
    names = []
    for n, (a, b) in enumerate([(0, 3), (3, 4), (4, 7)]):  # subdim 3: slabs of unequal thickness
        names.append(f"slab{n}.raw")
        (tmp_path / names[-1]).write_bytes(data[a:b].tobytes())
    _nhdr(tmp_path / "l.nhdr", "LIST 3\n" + "\n".join(names) + "\n")
    vol = volumen.load(tmp_path / "l.nhdr")
    assert np.array_equal(vol.data, data)


def test_nhdr_ascii(tmp_path):
    data = make_data(np.int16)
    (tmp_path / "a.txt").write_text("\n".join(" ".join(map(str, row)) for row in data.reshape(-1, 11)))
    _nhdr(tmp_path / "a.nhdr", "a.txt\n", enc="ascii")
    assert np.array_equal(volumen.load(tmp_path / "a.nhdr").data, data)


# -- MetaImage against SimpleITK ---------------------------------------------------
@pytest.mark.parametrize("suffix", [".mha", ".mhd"])
def test_metaimage_matches_simpleitk(tmp_path, suffix):
    vol = make_volume(np.int16)
    path = tmp_path / f"v{suffix}"
    volumen.save(vol, path)
    img = sitk.ReadImage(str(path))
    assert np.array_equal(sitk.GetArrayFromImage(img), vol.data)
    assert img.GetSize() == SHAPE[::-1] and img.GetSpacing() == SPACING[::-1]
    for ijk in IJK:
        lps = np.array(img.TransformIndexToPhysicalPoint([int(v) for v in ijk]))
        np.testing.assert_allclose(LPS @ lps, vol.index_to_world(ijk), rtol=0, atol=1e-12)


def test_metaimage_written_by_simpleitk(tmp_path):
    aff = oblique_affine()
    img = sitk.GetImageFromArray(make_data(np.float32))
    img.SetSpacing(SPACING[::-1])
    img.SetOrigin(LPS @ aff[:3, 3])
    img.SetDirection((LPS @ rotation(0.31, -0.17, 0.52)).ravel())
    path = tmp_path / "itk.mha"
    sitk.WriteImage(img, str(path))
    vol = volumen.load(path)
    assert np.array_equal(vol.data, make_data(np.float32)) and vol.spacing == SPACING
    np.testing.assert_allclose(vol.affine, aff, rtol=0, atol=1e-12)
    for ijk in IJK:
        lps = np.array(img.TransformIndexToPhysicalPoint([int(v) for v in ijk]))
        np.testing.assert_allclose(vol.index_to_world(ijk), LPS @ lps, rtol=0, atol=1e-12)


def test_mhd_with_zraw_written_by_hand(tmp_path):
    data = make_data(np.int16)
    packed = zlib.compress(data.tobytes())
    (tmp_path / "z.zraw").write_bytes(packed)
    (tmp_path / "z.mhd").write_text(
        "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
        f"CompressedData = True\nCompressedDataSize = {len(packed)}\n"
        "TransformMatrix = 0 1 0 -1 0 0 0 0 1\nOffset = 5 6 7\nElementSpacing = 1.3 0.7 2.5\n"
        "DimSize = 11 9 7\nElementType = MET_SHORT\nElementDataFile = z.zraw\n")
    vol = volumen.load(tmp_path / "z.mhd")
    assert np.array_equal(vol.data, data)
    # MetaIO's TransformMatrix lists direction columns: i -> (0, 1, 0) LPS, j -> (-1, 0, 0) LPS
    img = sitk.ReadImage(str(tmp_path / "z.mhd"))
    for ijk in IJK:
        lps = np.array(img.TransformIndexToPhysicalPoint([int(v) for v in ijk]))
        np.testing.assert_allclose(vol.index_to_world(ijk), LPS @ lps, rtol=0, atol=1e-12)
    np.testing.assert_allclose(vol.index_to_world([1, 1, 1]), [-5 + 0.7, -6 - 1.3, 7 + 2.5], atol=1e-12)


# -- VTK legacy, written by hand -----------------------------------------------------
VTK_TYPES = {"unsigned_char": "u1", "char": "i1", "short": "i2", "unsigned_short": "u2", "int": "i4",
             "unsigned_int": "u4", "float": "f4", "double": "f8"}


def write_vtk(path, data: np.ndarray, vtk_type: str, binary: bool, ncomp: int = 1, spacing_word="SPACING",
              origin_first=True):
    nz, ny, nx = data.shape[:3]
    geometry = [f"DIMENSIONS {nx} {ny} {nz}\n", f"{spacing_word} 1.3 0.7 2.5\n", "ORIGIN 10 -20 30.5\n"]
    if origin_first:  # any order is legal; ITK's reader wants DIMENSIONS first
        geometry = geometry[::-1]
    head = (f"# vtk DataFile Version 3.0\nmade by the test\n{'BINARY' if binary else 'ASCII'}\n"
            f"DATASET STRUCTURED_POINTS\n{''.join(geometry)}POINT_DATA {nx * ny * nz}\n"
            f"SCALARS values {vtk_type} {ncomp}\nLOOKUP_TABLE default\n").encode()
    if binary:
        body = data.astype(np.dtype(VTK_TYPES[vtk_type]).newbyteorder(">")).tobytes() + b"\n"
    else:
        body = "\n".join(" ".join(repr(v.item()) for v in row) for row in data.reshape(-1, nx * ncomp)).encode()
    path.write_bytes(head + body + b"\n")


@pytest.mark.parametrize("binary", [False, True])
@pytest.mark.parametrize("vtk_type", list(VTK_TYPES))
def test_vtk_legacy_types(tmp_path, vtk_type, binary):
    dt = np.dtype(VTK_TYPES[vtk_type])
    rng = np.random.default_rng(11)
    if dt.kind == "f":
        data = rng.normal(0, 50, SHAPE).astype(dt)
    else:
        info = np.iinfo(dt)
        data = rng.integers(max(info.min, -30000), min(info.max, 60000), SHAPE, endpoint=True).astype(dt)
    path = tmp_path / "v.vtk"
    write_vtk(path, data, vtk_type, binary)
    vol = volumen.load(path)
    assert vol.data.dtype == dt and np.array_equal(vol.data, data)
    assert vol.spacing == (2.5, 0.7, 1.3)
    # the file's frame is LPS: voxel (i, j, k) is at LPS origin + (1.3 i, 0.7 j, 2.5 k)
    assert np.array_equal(vol.affine, np.array([[-1.3, 0, 0, -10], [0, -0.7, 0, 20], [0, 0, 2.5, 30.5],
                                                [0, 0, 0, 1]]))


@pytest.mark.parametrize("binary", [False, True])
def test_vtk_geometry_matches_simpleitk(tmp_path, binary):
    data = make_data(np.int16)
    path = tmp_path / "s.vtk"
    write_vtk(path, data, "short", binary, origin_first=False)
    vol = volumen.load(path)
    img = sitk.ReadImage(str(path))  # ITK's VTKImageIO: an independent reader
    assert np.array_equal(sitk.GetArrayFromImage(img), vol.data)
    for ijk in IJK:
        lps = np.array(img.TransformIndexToPhysicalPoint([int(v) for v in ijk]))
        np.testing.assert_allclose(vol.index_to_world(ijk), LPS @ lps, rtol=0, atol=1e-12)


def test_vtk_aspect_ratio_and_components(tmp_path):
    data = np.random.default_rng(2).normal(size=SHAPE + (3,)).astype(np.float32)
    path = tmp_path / "c.vtk"
    write_vtk(path, data, "float", True, ncomp=3, spacing_word="ASPECT_RATIO")
    vol = volumen.load(path)
    assert np.array_equal(vol.data, data[..., 0]) and vol.spacing == (2.5, 0.7, 1.3)
    assert any("first only" in w for w in vol.meta["warnings"])


# -- raw ------------------------------------------------------------------------------
@pytest.mark.parametrize("order,code", [("little", "<"), ("big", ">"), ("<", "<"), (">", ">")])
def test_raw_byte_orders(tmp_path, order, code):
    data = make_data(np.int16)
    path = tmp_path / "v.raw"
    path.write_bytes(b"H" * 16 + data.astype(code + "i2").tobytes())
    vol = volumen.load(path, shape=SHAPE, dtype="int16", spacing=SPACING, byte_order=order, offset=16)
    assert vol.data.dtype == np.int16 and vol.data.dtype.isnative
    assert np.array_equal(vol.data, data)
    assert vol.spacing == SPACING and np.array_equal(vol.affine, np.diag([1.3, 0.7, 2.5, 1.0]))


def test_raw_with_affine(tmp_path):
    data = make_data(np.float32)
    path = tmp_path / "v.bin"
    data.astype(">f4").tofile(path)
    vol = volumen.load(path, shape=SHAPE, dtype=np.float32, byte_order="big", affine=oblique_affine())
    assert np.array_equal(vol.data, data) and np.array_equal(vol.affine, oblique_affine())
    np.testing.assert_allclose(vol.spacing, SPACING, rtol=1e-12)


def test_npy_sidecar_is_plain_json(tmp_path):
    vol = make_volume(np.uint8)
    volumen.save(vol, tmp_path / "v.npy")
    rec = json.loads((tmp_path / "v.npy.json").read_text())
    assert rec["spacing"] == list(SPACING) and np.array_equal(np.array(rec["affine"]), vol.affine)
