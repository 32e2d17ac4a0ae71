"""DICOM as people have it, built from pydicom's own files: empty or missing tags, colour, float pixels,
legacy multi-frame without positions, detector spacings, and folders holding a corrupt file and two series."""

import json

import numpy as np
import pydicom
import pytest
import SimpleITK as sitk
from pydicom.data import get_palette_files, get_testdata_file
from pydicom.pixels import apply_color_lut

import volumen
from volumen.cli import main
from volumen.errors import CorruptDataError
from volumen.io import list_series

RAS = np.array([-1.0, -1.0, 1.0])


def _ct(**edits):
    """pydicom's CT_small.dcm with ``edits`` (name -> value, or None to delete)."""
    ds = pydicom.dcmread(get_testdata_file("CT_small.dcm"))
    for key, value in edits.items():
        if value is None:
            if key in ds:
                delattr(ds, key)
        else:
            setattr(ds, key, value)
    return ds


def _series(folder, n=4, uid="1.2.826.0.1.3680043.8.498.1", number=1, description="first", gap=2.5, **edits):
    """``n`` copies of CT_small.dcm ``gap`` mm apart along z, one series."""
    folder.mkdir(parents=True, exist_ok=True)
    for k in range(n):
        ds = _ct(**edits)
        ds.SeriesInstanceUID, ds.SeriesNumber, ds.SeriesDescription = uid, number, description
        ds.SOPInstanceUID = f"{uid}.{k + 1}"
        ds.ImagePositionPatient = [-158.1, -179.0, -75.7 + gap * k]
        ds.InstanceNumber = k + 1
        ds.save_as(folder / f"{description}_{k}.dcm")
    return folder


def test_empty_sop_class_empty_strings_and_missing_optional_tags(tmp_path):
    """TotalSegmentator's example series has SOPClassUID = ''; others leave strings empty or drop tags."""
    folder = _series(tmp_path / "s", SOPClassUID="", Manufacturer="", SeriesDescription="", SliceThickness="",
                     RescaleType="", WindowCenter=None, WindowWidth=None, StudyDescription=None, Modality="")
    for p in folder.iterdir():
        ds = pydicom.dcmread(p)
        ds.file_meta.MediaStorageSOPClassUID = ""
        ds.save_as(p)
    vol = volumen.load(folder)
    ref = pydicom.dcmread(get_testdata_file("CT_small.dcm"))
    assert vol.shape == (4, 128, 128) and vol.spacing[0] == pytest.approx(2.5, abs=1e-6)
    np.testing.assert_array_equal(vol.data[0], ref.pixel_array * float(ref.RescaleSlope) + float(ref.RescaleIntercept))
    assert vol.meta["sop_class"] == "" and vol.modality == "OT"
    assert [s.uid for s in list_series(folder)] == ["1.2.826.0.1.3680043.8.498.1"]


def test_folder_with_a_corrupt_file_and_two_series(tmp_path):
    folder = _series(tmp_path / "f", n=3)
    _series(folder, n=5, uid="1.2.826.0.1.3680043.8.498.2", number=2, description="second", gap=1.0)
    (folder / "broken.dcm").write_bytes(b"DICM" + b"\x00" * 40)
    notes = []
    series = list_series(folder, notes)
    assert [(s.number, s.description, s.size, s.files) for s in series] == [
        ("1", "first", (128, 128, 3), 3), ("2", "second", (128, 128, 5), 5)]
    assert [n for n in notes if "broken.dcm" in n]
    vol = volumen.load(folder, series=series[1].uid)
    assert vol.shape == (5, 128, 128) and vol.spacing[0] == pytest.approx(1.0, abs=1e-6)
    assert [w for w in vol.meta["warnings"] if "broken.dcm" in w]
    with pytest.raises(CorruptDataError, match="broken.dcm"):
        volumen.load(folder / "broken.dcm")


def test_cli_info_lists_every_series(tmp_path, capsys):
    folder = _series(tmp_path / "f", n=2)
    _series(folder, n=3, uid="1.2.826.0.1.3680043.8.498.2", number=2, description="second")
    assert main(["info", str(folder)]) == 0
    out = capsys.readouterr().out
    assert "2 image series" in out and "first" in out and "second" in out and "1.2.826.0.1.3680043.8.498.2" in out
    assert main(["info", str(folder), "--json"]) == 0
    listing = json.loads(capsys.readouterr().out)["series"]
    assert [(s["description"], s["files"], s["modality"]) for s in listing] == [("first", 2, "CT"), ("second", 3, "CT")]
    assert main(["info", str(folder), "--series", "1.2.826.0.1.3680043.8.498.2", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["shape_zyx"] == [3, 128, 128]


@pytest.mark.parametrize("palette", ["own", "hotiron"])
def test_palette_colour_is_expanded_through_its_lut(tmp_path, palette):
    """pydicom's PALETTE COLOR example, with its own 16-bit LUT (RGB = LUT[index] >> 8) or pydicom's 8-bit hotiron
    palette (RGB = LUT[index])."""
    ds = pydicom.dcmread(get_testdata_file("examples_palette.dcm"))
    if palette != "own":
        pal = pydicom.dcmread(get_palette_files(f"{palette}.dcm")[0])
        for c in ("Red", "Green", "Blue"):
            for tag in (f"{c}PaletteColorLookupTableDescriptor", f"{c}PaletteColorLookupTableData"):
                ds[tag] = pal[tag]
    ds.save_as(tmp_path / "pal.dcm")
    vol = volumen.load(tmp_path / "pal.dcm")
    expected = apply_color_lut(ds.pixel_array, ds)
    assert vol.is_color and vol.dtype == np.uint8
    np.testing.assert_array_equal(vol.data[0], expected >> 8 if expected.dtype == np.uint16 else expected)
    lum = vol.luminance()
    assert lum.shape == vol.shape and lum.max() > lum.min()


@pytest.mark.parametrize("tag, dtype", [("FloatPixelData", np.float32), ("DoubleFloatPixelData", np.float64)])
def test_float_pixel_data(tmp_path, tag, dtype):
    ds = _ct(PixelData=None, RescaleSlope=None, RescaleIntercept=None, BitsStored=None, HighBit=None,
             PixelRepresentation=None, SmallestImagePixelValue=None, LargestImagePixelValue=None)
    values = np.linspace(-1.5, 2.5, 128 * 128, dtype=dtype).reshape(128, 128)
    ds.BitsAllocated = 8 * np.dtype(dtype).itemsize
    setattr(ds, tag, values.tobytes())
    ds.save_as(tmp_path / "float.dcm")
    vol = volumen.load(tmp_path / "float.dcm")
    assert vol.dtype == dtype
    np.testing.assert_array_equal(vol.data[0], values)


def test_voi_lut_is_reported_not_applied(tmp_path):
    ds = _ct()
    voi = pydicom.Dataset()
    voi.LUTDescriptor = [4096, 0, 16]
    voi.LUTData = (np.arange(4096, dtype=np.uint16) // 16).tobytes()
    voi.LUTExplanation = "soft tissue"
    ds.VOILUTSequence = [voi]
    ds.save_as(tmp_path / "voi.dcm")
    vol = volumen.load(tmp_path / "voi.dcm")
    np.testing.assert_array_equal(vol.data, volumen.load(get_testdata_file("CT_small.dcm")).data)
    assert "soft tissue" in vol.meta["voi_lut"] and "not applied" in vol.meta["voi_lut"]


def test_legacy_multiframe_without_positions_gets_a_stated_spacing():
    """pydicom's 30-frame YBR ultrasound clip: no positions, no spacing -> 1 mm apart, with a warning."""
    path = get_testdata_file("examples_ybr_color.dcm")
    vol = volumen.load(path)
    ref = sitk.GetArrayFromImage(sitk.ReadImage(path))
    assert vol.is_color and vol.data.shape == ref.shape == (30, 240, 320, 3)
    np.testing.assert_array_equal(vol.data, ref)
    assert vol.spacing[0] == 1.0 and [w for w in vol.meta["warnings"] if "30 frames assumed evenly spaced 1 mm" in w]


@pytest.mark.parametrize("tag", ["ImagerPixelSpacing", "ImagePlanePixelSpacing"])
def test_detector_pixel_spacing_is_used_with_a_note(tmp_path, tag):
    ds = _ct(PixelSpacing=None)
    setattr(ds, tag, [0.3, 0.4])
    ds.save_as(tmp_path / "x.dcm")
    vol = volumen.load(tmp_path / "x.dcm")
    assert vol.spacing[1:] == pytest.approx((0.3, 0.4))
    assert [w for w in vol.meta["warnings"] if tag in w]


@pytest.mark.parametrize("spacing", [[0, 0], [-0.5, 0.5]])
def test_zero_or_negative_pixel_spacing_is_1mm_with_a_warning(tmp_path, spacing):
    _ct(PixelSpacing=spacing).save_as(tmp_path / "x.dcm")
    vol = volumen.load(tmp_path / "x.dcm")
    assert vol.spacing[1:] == (1.0, 1.0) and [w for w in vol.meta["warnings"] if "not positive" in w]


def test_modality_lut_sequence_is_applied(tmp_path):
    """A Modality LUT Sequence replaces the linear rescale: values = LUT[stored - first mapped]."""
    ds = _ct(RescaleSlope=None, RescaleIntercept=None)
    lut = pydicom.Dataset()
    first = int(ds.pixel_array.min())
    n = int(ds.pixel_array.max()) - first + 1
    lut.LUTDescriptor = [n, first, 16]
    lut.LUTData = (3 * np.arange(n, dtype=np.uint16)).tobytes()
    lut.ModalityLUTType = "US"
    lut.LUTExplanation = "times three"
    ds.ModalityLUTSequence = [lut]
    ds.save_as(tmp_path / "lut.dcm")
    vol = volumen.load(tmp_path / "lut.dcm")
    np.testing.assert_array_equal(vol.data[0], 3 * (ds.pixel_array.astype(int) - first))
    assert "times three" in vol.meta["modality_lut"]


@pytest.mark.parametrize("syntax", [pydicom.uid.RLELossless, pydicom.uid.JPEGLSLossless, pydicom.uid.JPEG2000Lossless,
                                    pydicom.uid.DeflatedExplicitVRLittleEndian])
def test_lossless_syntaxes_round_trip_exactly(tmp_path, syntax):
    """CT_small.dcm compressed by pydicom's encoders (or deflated) loads to the same HU as the original."""
    ds = pydicom.dcmread(get_testdata_file("CT_small.dcm"))
    original = volumen.load(get_testdata_file("CT_small.dcm"))
    if syntax == pydicom.uid.DeflatedExplicitVRLittleEndian:
        ds.file_meta.TransferSyntaxUID = syntax
    else:
        ds.compress(syntax)
    ds.save_as(tmp_path / "x.dcm")
    vol = volumen.load(tmp_path / "x.dcm")
    assert vol.meta["transfer_syntax_uid"] == syntax
    np.testing.assert_array_equal(vol.data, original.data)
    np.testing.assert_allclose(vol.affine, original.affine)


def test_colour_volume_is_refused_by_writers_with_a_typed_error(tmp_path):
    from volumen.errors import VolumeWriteError

    vol = volumen.load(get_testdata_file("SC_rgb_jpeg_dcmtk.dcm"))
    for name in ("x.nii.gz", "x.nrrd", "x.mha", "x.npy"):
        with pytest.raises(VolumeWriteError, match="colour"):
            volumen.save(vol, tmp_path / name)
    grey = vol.with_data(vol.luminance())
    volumen.save(grey, tmp_path / "grey.nii.gz")
    np.testing.assert_allclose(volumen.load(tmp_path / "grey.nii.gz").data, vol.luminance(), rtol=1e-6)


def test_a_series_with_a_broken_file_of_its_own_refuses_and_the_others_load(tmp_path):
    folder = _series(tmp_path / "f", n=3)
    _series(folder, n=4, uid="1.2.826.0.1.3680043.8.498.2", number=2, description="second")
    broken = folder / "first_1.dcm"
    iop = "\\".join(v.original_string for v in pydicom.dcmread(broken).ImageOrientationPatient).encode()
    raw = broken.read_bytes()
    assert raw.count(iop) == 1
    broken.write_bytes(raw.replace(iop, b"x" + iop[1:]))  # not numbers; the file's series is still known
    with pytest.raises(CorruptDataError, match="first_1.dcm.*ImageOrientationPatient"):
        volumen.load(folder, series="1.2.826.0.1.3680043.8.498.1")
    assert [(s.files, s.unreadable) for s in list_series(folder)] == [(2, 1), (4, 0)]
    assert volumen.load(folder, series="1.2.826.0.1.3680043.8.498.2").shape == (4, 128, 128)
