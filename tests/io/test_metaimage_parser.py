"""volumen parses MetaImage itself; SimpleITK is the independent reader it must agree with."""

from __future__ import annotations

import numpy as np
import pytest
import SimpleITK as sitk

import volumen
from volumen.data import shared_data, shared_data_candidates

AORTA = shared_data("vmtk-aorta", "aorta.mha")
FLIP = np.diag([-1.0, -1.0, 1.0, 1.0])


def sitk_volume(path):
    """Data and RAS+ affine as SimpleITK reads ``path``."""
    img = sitk.ReadImage(str(path))
    d = np.array(img.GetDirection()).reshape(3, 3)
    lps = np.eye(4)
    lps[:3, :3] = d * np.array(img.GetSpacing())
    lps[:3, 3] = img.GetOrigin()
    return sitk.GetArrayFromImage(img), FLIP @ lps


def test_shared_aorta_matches_simpleitk():
    if AORTA is None:
        pytest.skip(f"VMTK aorta not in the shared data folder (looked in {shared_data_candidates()})")
    vol = volumen.load(AORTA)
    data, affine = sitk_volume(AORTA)
    assert vol.data.dtype == data.dtype and np.array_equal(vol.data, data)
    assert np.abs(vol.affine - affine).max() <= 1e-12


def _oblique_image(dtype, channels=1):
    rng = np.random.default_rng(4)
    c, s = np.cos(0.4), np.sin(0.4)
    rot = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]) @ np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    shape = (3, 4, 5) + ((channels,) if channels > 1 else ())
    img = sitk.GetImageFromArray((rng.random(shape) * 100).astype(dtype), isVector=channels > 1)
    img.SetSpacing((0.5, 0.7, 2.0))
    img.SetOrigin((1.5, -2.0, 3.25))
    img.SetDirection(rot.ravel().tolist())
    return img


@pytest.mark.parametrize("name,compress", [("o.mha", False), ("o.mha", True), ("o.mhd", False), ("o.mhd", True)])
@pytest.mark.parametrize("dtype", [np.int16, np.uint8, np.float64])
def test_oblique_files_written_by_simpleitk(tmp_path, name, compress, dtype):
    path = tmp_path / name
    sitk.WriteImage(_oblique_image(dtype), str(path), useCompression=compress)
    vol = volumen.load(path)
    data, affine = sitk_volume(path)
    assert np.array_equal(vol.data, data)
    assert np.abs(vol.affine - affine).max() <= 1e-12  # same 17-digit numbers, same products


def test_vector_image_reads_first_channel(tmp_path):
    path = tmp_path / "v.mha"
    sitk.WriteImage(_oblique_image(np.float32, channels=3), str(path))
    vol = volumen.load(path)
    assert np.array_equal(vol.data, sitk.GetArrayFromImage(sitk.ReadImage(str(path)))[..., 0])
    assert any("components" in w for w in vol.meta["warnings"])


HEAD = ("ObjectType = Image\nNDims = 3\nDimSize = 5 4 3\nElementSpacing = 0.5 0.7 2\nOffset = 1 2 3\n"
        "TransformMatrix = 1 0 0 0 1 0 0 0 1\n")
DATA = np.arange(60, dtype=np.int16).reshape(3, 4, 5) * 7 - 100


@pytest.mark.parametrize("form", ["list", "pattern", "big-endian", "ascii", "header-size-minus-one"])
def test_data_forms_agree_with_simpleitk(tmp_path, form):
    path = tmp_path / "f.mhd"
    if form == "list":
        for k in range(3):
            (tmp_path / f"s{k}.raw").write_bytes(DATA[k].tobytes())
        path.write_text(HEAD + "ElementType = MET_SHORT\nElementDataFile = LIST 2D\ns0.raw\ns1.raw\ns2.raw\n")
    elif form == "pattern":
        for k in range(3):
            (tmp_path / f"s{k + 1:03d}.raw").write_bytes(DATA[k].tobytes())
        path.write_text(HEAD + "ElementType = MET_SHORT\nElementDataFile = s%03d.raw 1 3 1\n")
    elif form == "big-endian":
        (tmp_path / "b.raw").write_bytes(DATA.astype(">i2").tobytes())
        path.write_text(HEAD + "BinaryDataByteOrderMSB = True\nElementType = MET_SHORT\nElementDataFile = b.raw\n")
    elif form == "ascii":
        path = tmp_path / "a.mha"
        path.write_text(HEAD + "BinaryData = False\nElementType = MET_SHORT\nElementDataFile = LOCAL\n"
                        + " ".join(map(str, DATA.ravel())))
    else:
        (tmp_path / "h.raw").write_bytes(b"junk header" + DATA.tobytes())
        path.write_text(HEAD + "HeaderSize = -1\nElementType = MET_SHORT\nElementDataFile = h.raw\n")
    vol = volumen.load(path)
    assert np.array_equal(vol.data, DATA)
    expected = np.array([[-0.5, 0, 0, -1], [0, -0.7, 0, -2], [0, 0, 2, 3], [0, 0, 0, 1]])  # LPS header -> RAS
    assert np.abs(vol.affine - expected).max() <= 1e-12
    if form != "ascii":  # SimpleITK 2.x fails on ASCII data ("M_ReadElementsData: file stream is fail")
        data, affine = sitk_volume(path)
        assert np.array_equal(data, DATA) and np.abs(vol.affine - affine).max() <= 1e-12
