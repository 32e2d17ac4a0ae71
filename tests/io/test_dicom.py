"""DICOM reader: geometry against the DICOM definition and SimpleITK, values, series, errors, privacy.

Every test writes its own small series with pydicom (tests/io/dicom_factory.py).
Expected affines are built here from the tags that were written: a pixel (column i,
row j) of the slice at ImagePositionPatient P lies at ``P + i*dx*row_dir + j*dy*col_dir``
(LPS, DICOM PS3.3 C.7.6.2.1.1); RAS+ negates x and y.
"""

from __future__ import annotations

import numpy as np
import pydicom
import pytest
from pydicom.uid import HTJ2KLossless, JPEG2000Lossless, JPEGLosslessSV1, JPEGLSLossless

import volumen
from tests.io.dicom_factory import (
    PATIENT,
    new_uid,
    oblique_cosines,
    stack_positions,
    write_enhanced,
    write_legacy_multiframe,
    write_non_image,
    write_series,
)
from volumen.errors import (
    CorruptDataError,
    MissingDependencyError,
    MissingPathError,
    MultipleSeriesError,
    SeriesError,
    UnknownFormatError,
    VolumeReadError,
)
from volumen.io import _dicom

ROW, COL = oblique_cosines(axis=(1.0, 0.3, 0.0), degrees=20.0)
ORIGIN = np.array([-100.5, 80.25, 30.0])
PS = (0.8, 0.6)  # PixelSpacing: (row spacing dy, column spacing dx)
RAS = np.array([-1.0, -1.0, 1.0])


def raw_stack(n, rows=16, cols=20, seed=0, lo=0, hi=3000, dtype=np.int16):
    return np.random.default_rng(seed).integers(lo, hi, size=(n, rows, cols)).astype(dtype)


def dicom_affine(row, col, ps, first, last, n):
    """The RAS+ affine the reader should produce, from the tags of the first and last slice."""
    m = np.eye(4)
    m[:3, 0] = np.asarray(row) * ps[1]
    m[:3, 1] = np.asarray(col) * ps[0]
    m[:3, 2] = (np.asarray(last) - np.asarray(first)) / (n - 1)
    m[:3, 3] = first
    return np.diag([-1.0, -1.0, 1.0, 1.0]) @ m


def pixel_world_ras(position, i, j, row=ROW, col=COL, ps=PS):
    """RAS+ mm of pixel (column i, row j) of a slice at ``position`` (LPS)."""
    return (np.asarray(position) + i * ps[1] * np.asarray(row) + j * ps[0] * np.asarray(col)) * RAS


# -- geometry and values ------------------------------------------------------------------------

def test_oblique_shuffled_ct_values_and_affine(tmp_path):
    n = 12
    raw = raw_stack(n)
    offsets = 40.0 - 1.25 * np.arange(n)           # written slice k lies *below* slice k-1
    pos = stack_positions(ORIGIN, ROW, COL, offsets)
    write_series(tmp_path / "ct", raw, row_dir=ROW, col_dir=COL, positions=pos, pixel_spacing=PS,
                 slope=0.5, intercept=-1024, shuffle_seed=3)
    vol = volumen.load(tmp_path / "ct")

    # ascending along the normal = reverse of the written order; no slice lost
    np.testing.assert_array_equal(vol.data, (raw[::-1].astype(np.float64) * 0.5 - 1024).astype(np.float32))
    assert vol.data.dtype == np.float32 and vol.shape == (n, 16, 20)
    sorted_pos = pos[::-1]
    np.testing.assert_allclose(vol.affine, dicom_affine(ROW, COL, PS, sorted_pos[0], sorted_pos[-1], n), atol=1e-6)
    np.testing.assert_allclose(vol.spacing, (1.25, 0.8, 0.6), atol=1e-6)
    for k in (0, 5, n - 1):
        for i, j in ((0, 0), (19, 0), (0, 15), (7, 11)):
            np.testing.assert_allclose(vol.index_to_world([i, j, k]), pixel_world_ras(sorted_pos[k], i, j), atol=1e-6)
    np.testing.assert_allclose(np.diff(vol.meta["slice_positions"]), 1.25, atol=1e-6)
    assert vol.modality == "CT" and vol.units == "HU" and vol.name == "test series"
    assert vol.meta["rescale"] == {"slope": 0.5, "intercept": -1024.0}
    assert vol.meta["window_presets"][0]["center"] == 40.0 and vol.meta["n_files"] == n
    assert vol.meta["warnings"] == [] and vol.is_oblique


def test_list_of_files_in_any_order_equals_folder(tmp_path):
    n = 8
    raw = raw_stack(n, seed=1)
    paths = write_series(tmp_path / "s", raw, row_dir=ROW, col_dir=COL,
                         positions=stack_positions(ORIGIN, ROW, COL, 2.0 * np.arange(n)), slope=0.5, intercept=-1024)
    a = volumen.load(tmp_path / "s")
    b = volumen.load([str(p) for p in paths[::-1]])
    np.testing.assert_array_equal(a.data, b.data)
    np.testing.assert_allclose(a.affine, b.affine, atol=1e-12)


def test_slope_and_intercept_differing_between_slices(tmp_path):
    n = 10
    raw = raw_stack(n, seed=2)
    slopes = 0.25 + 0.125 * np.arange(n)
    intercepts = -1024.0 + 3.0 * np.arange(n)
    write_series(tmp_path / "s", raw, row_dir=ROW, col_dir=COL, slope=slopes, intercept=intercepts,
                 positions=stack_positions(ORIGIN, ROW, COL, np.arange(n)))
    vol = volumen.load(tmp_path / "s")
    expected = raw * slopes[:, None, None] + intercepts[:, None, None]
    assert vol.data.dtype == np.float32
    np.testing.assert_allclose(vol.data, expected, rtol=0, atol=1e-4)
    assert vol.meta["rescale"]["per_slice"] and vol.meta["rescale"]["slope_range"] == [0.25, slopes[-1]]


def test_whole_number_rescale_keeps_an_integer_dtype(tmp_path):
    raw = raw_stack(6, seed=3, lo=0, hi=4000, dtype=np.uint16)
    write_series(tmp_path / "s", raw, row_dir=ROW, col_dir=COL, slope=1, intercept=-1024,
                 positions=stack_positions(ORIGIN, ROW, COL, np.arange(6)))
    vol = volumen.load(tmp_path / "s")
    assert vol.data.dtype == np.int16
    np.testing.assert_array_equal(vol.data, raw.astype(np.int32) - 1024)


def test_matches_simpleitk(tmp_path):
    sitk = pytest.importorskip("SimpleITK")
    n = 9
    raw = raw_stack(n, seed=4, lo=-500, hi=2500)
    folder = tmp_path / "s"
    write_series(folder, raw, row_dir=ROW, col_dir=COL, positions=stack_positions(ORIGIN, ROW, COL, 1.5 * np.arange(n)),
                 pixel_spacing=PS, slope=1, intercept=-1024, shuffle_seed=7)
    vol = volumen.load(folder)
    reader = sitk.ImageSeriesReader()
    reader.SetFileNames(reader.GetGDCMSeriesFileNames(str(folder)))
    img = reader.Execute()
    np.testing.assert_array_equal(vol.data, sitk.GetArrayFromImage(img))        # both [z, y, x]
    np.testing.assert_allclose(vol.origin, np.array(img.GetOrigin()) * RAS, atol=1e-4)
    direction_lps = np.array(img.GetDirection()).reshape(3, 3)                  # columns: i, j, k
    np.testing.assert_allclose(vol.direction, RAS[:, None] * direction_lps, atol=1e-5)
    np.testing.assert_allclose(vol.spacing, img.GetSpacing()[::-1], rtol=1e-5)


def test_gantry_tilt_keeps_the_shear(tmp_path):
    n = 8
    raw = raw_stack(n, seed=5)
    row, col = np.array([1.0, 0, 0]), np.array([0, 1.0, 0])
    step = np.array([0.0, 0.3, 1.2])                     # each slice moves 1.2 mm up and 0.3 mm back
    pos = ORIGIN + np.arange(n)[:, None] * step
    write_series(tmp_path / "s", raw, row_dir=row, col_dir=col, positions=pos, pixel_spacing=PS)
    vol = volumen.load(tmp_path / "s")
    np.testing.assert_allclose(vol.affine, dicom_affine(row, col, PS, pos[0], pos[-1], n), atol=1e-6)
    assert vol.spacing[0] == pytest.approx(np.linalg.norm(step), abs=1e-6)
    assert vol.meta["gantry_tilt_deg"] == pytest.approx(np.degrees(np.arctan2(0.3, 1.2)), abs=1e-6)
    np.testing.assert_allclose(vol.index_to_world([3, 4, 5]), pixel_world_ras(pos[5], 3, 4, row, col), atol=1e-6)
    np.testing.assert_array_equal(vol.data, raw)


def test_single_slice_uses_slice_thickness(tmp_path):
    raw = raw_stack(1, seed=6)
    p = write_series(tmp_path / "s", raw, row_dir=ROW, col_dir=COL, positions=ORIGIN[None], slice_thickness=2.5)[0]
    vol = volumen.load(p)
    assert vol.shape == (1, 16, 20) and vol.spacing[0] == pytest.approx(2.5)
    np.testing.assert_allclose(vol.affine[:3, 2], np.cross(ROW, COL) * 2.5 * RAS, atol=1e-6)
    assert any("single-slice" in w for w in vol.meta["warnings"])
    q = write_series(tmp_path / "t", raw, row_dir=ROW, col_dir=COL, positions=ORIGIN[None], slice_thickness=None)[0]
    assert volumen.load(q).spacing[0] == pytest.approx(1.0)


# -- non-uniform spacing --------------------------------------------------------------------------

def test_non_uniform_spacing_loads_with_warning_and_resamples(tmp_path):
    offsets = np.array([0.0, 1.0, 2.0, 4.0, 5.0, 8.0, 9.0, 10.0])
    n = len(offsets)
    yy, xx = np.mgrid[:16, :20]
    raw = (10 * offsets[:, None, None] + yy + 2 * xx).astype(np.int16)   # linear along the normal
    pos = stack_positions(ORIGIN, ROW, COL, offsets)
    write_series(tmp_path / "s", raw, row_dir=ROW, col_dir=COL, positions=pos, pixel_spacing=PS, shuffle_seed=1)
    p0 = float(pos[0] @ np.cross(ROW, COL))

    vol = volumen.load(tmp_path / "s")
    np.testing.assert_array_equal(vol.data, raw)                            # nothing dropped or reordered
    np.testing.assert_allclose(vol.meta["slice_positions"], p0 + offsets, atol=1e-6)
    assert any("non-uniform" in w for w in vol.meta["warnings"])
    np.testing.assert_allclose(vol.affine, dicom_affine(ROW, COL, PS, pos[0], pos[-1], n), atol=1e-6)

    res = volumen.load(tmp_path / "s", resample=True)
    assert res.shape == (11, 16, 20) and res.spacing[0] == pytest.approx(1.0, abs=1e-6)
    t = np.arange(11.0)
    np.testing.assert_allclose(res.data, 10 * t[:, None, None] + yy + 2 * xx, atol=1e-4)
    np.testing.assert_allclose(res.meta["slice_positions"], p0 + t, atol=1e-6)
    np.testing.assert_allclose(res.meta["source_slice_positions"], p0 + offsets, atol=1e-6)
    assert "resampled" in res.meta
    # slice m of the new grid lies t[m] mm along the normal from the first slice
    world = res.index_to_world([[2, 3, m] for m in (0, 3, 6, 10)])
    expected = [pixel_world_ras(ORIGIN + tm * np.cross(ROW, COL), 2, 3) for tm in (0, 3, 6, 10)]
    np.testing.assert_allclose(world, expected, atol=1e-6)


# -- multi-frame ----------------------------------------------------------------------------------

@pytest.mark.parametrize("per_frame", [False, True])
def test_enhanced_multiframe_ct(tmp_path, per_frame):
    n = 10
    raw = raw_stack(n, seed=8)
    pos = stack_positions(ORIGIN, ROW, COL, 1.5 * np.arange(n))
    slopes = np.full(n, 0.25) if not per_frame else 0.25 + 0.25 * np.arange(n)
    intercepts = np.full(n, -1000.0) if not per_frame else -1000.0 + np.arange(n)
    path = write_enhanced(tmp_path / "mf.dcm", raw, row_dir=ROW, col_dir=COL, positions=pos, pixel_spacing=PS,
                          slope=slopes if per_frame else 0.25, intercept=intercepts if per_frame else -1000.0,
                          per_frame_rescale=per_frame, frame_order=np.random.default_rng(0).permutation(n))
    vol = volumen.load(path)
    np.testing.assert_allclose(vol.data, raw * slopes[:, None, None] + intercepts[:, None, None], atol=1e-4)
    np.testing.assert_allclose(vol.affine, dicom_affine(ROW, COL, PS, pos[0], pos[-1], n), atol=1e-6)
    assert vol.meta["multiframe"] and vol.meta["n_files"] == 1 and vol.units == "HU"
    np.testing.assert_allclose(vol.index_to_world([1, 2, 7]), pixel_world_ras(pos[7], 1, 2), atol=1e-6)


def test_enhanced_single_frame(tmp_path):
    raw = raw_stack(1, seed=9)
    path = write_enhanced(tmp_path / "one.dcm", raw, row_dir=ROW, col_dir=COL, positions=ORIGIN[None],
                          slope=0.5, intercept=-10)
    vol = volumen.load(path)
    np.testing.assert_allclose(vol.data, raw * 0.5 - 10, atol=1e-4)
    assert vol.spacing[0] == pytest.approx(1.5)  # SliceThickness in PixelMeasuresSequence


def test_legacy_multiframe_with_grid_frame_offsets(tmp_path):
    raw = raw_stack(6, seed=10, lo=0, hi=1000, dtype=np.uint16)
    offsets = np.array([0.0, 3.0, 6.0, 9.0, 12.0, 15.0])
    path = write_legacy_multiframe(tmp_path / "dose.dcm", raw, row_dir=ROW, col_dir=COL, position=ORIGIN,
                                   offsets=offsets, dose_scaling=0.001)
    vol = volumen.load(path)
    pos = stack_positions(ORIGIN, ROW, COL, offsets)
    np.testing.assert_allclose(vol.data, raw * 0.001, rtol=1e-6)
    np.testing.assert_allclose(vol.affine, dicom_affine(ROW, COL, (2.5, 2.0), pos[0], pos[-1], 6), atol=1e-6)
    assert vol.units == "GY" and vol.modality == "RTDOSE"
    # without offsets, SpacingBetweenSlices is used, with a warning
    path = write_legacy_multiframe(tmp_path / "nm.dcm", raw, row_dir=ROW, col_dir=COL, position=ORIGIN,
                                   spacing_between=4.0)
    vol = volumen.load(path)
    assert vol.spacing[0] == pytest.approx(4.0) and any("assumed evenly" in w for w in vol.meta["warnings"])


# -- several series -------------------------------------------------------------------------------

def test_several_series_need_a_choice(tmp_path):
    a, b = new_uid("series-a"), new_uid("series-b")
    write_series(tmp_path / "x" / "a", raw_stack(8), row_dir=ROW, col_dir=COL,
                 positions=stack_positions(ORIGIN, ROW, COL, np.arange(8)), series_uid=a, description="first")
    write_series(tmp_path / "x" / "b", raw_stack(10, seed=1), row_dir=ROW, col_dir=COL,
                 positions=stack_positions(ORIGIN, ROW, COL, np.arange(10)), series_uid=b, description="second")
    (tmp_path / "x" / "README.txt").write_text("not dicom")
    with pytest.raises(MultipleSeriesError) as err:
        volumen.load(tmp_path / "x")
    assert sorted(err.value.series) == sorted([(a, "first", 8), (b, "second", 10)])
    assert str(tmp_path / "x") in str(err.value) and a in str(err.value)
    assert volumen.load(tmp_path / "x", series=a).shape == (8, 16, 20)
    vb = volumen.load(tmp_path / "x", series=b)
    assert vb.shape == (10, 16, 20) and vb.name == "second" and vb.meta["series_uid"] == b
    with pytest.raises(SeriesError, match="no series") as err:
        volumen.load(tmp_path / "x", series="1.2.3.4")
    assert a in str(err.value) and b in str(err.value)


def test_non_image_dicom_and_dicomdir_are_skipped(tmp_path):
    write_series(tmp_path / "s", raw_stack(4), row_dir=ROW, col_dir=COL,
                 positions=stack_positions(ORIGIN, ROW, COL, np.arange(4)))
    write_non_image(tmp_path / "s" / "report.dcm")
    dicomdir = pydicom.Dataset()
    dicomdir.file_meta = pydicom.dataset.FileMetaDataset()
    dicomdir.file_meta.MediaStorageSOPClassUID = "1.2.840.10008.1.3.10"
    dicomdir.file_meta.MediaStorageSOPInstanceUID = new_uid("dicomdir")
    dicomdir.file_meta.TransferSyntaxUID = pydicom.uid.ExplicitVRLittleEndian
    dicomdir.FileSetID = "X"
    dicomdir.save_as(tmp_path / "s" / "DICOMDIR", enforce_file_format=True)
    vol = volumen.load(tmp_path / "s")
    assert vol.shape == (4, 16, 20)
    assert [w for w in vol.meta["warnings"] if "report.dcm" in w and "without pixel data" in w]
    assert not [w for w in vol.meta["warnings"] if "DICOMDIR" in w]


# -- bad input ------------------------------------------------------------------------------------

def _raises(exc_type, path, **kw):
    with pytest.raises(exc_type) as err:
        volumen.load(path, **kw)
    assert isinstance(err.value, VolumeReadError)
    return str(err.value)


def test_empty_folder_and_no_dicom(tmp_path):
    (tmp_path / "empty").mkdir()
    assert str(tmp_path / "empty") in _raises(UnknownFormatError, tmp_path / "empty")
    (tmp_path / "text").mkdir()
    (tmp_path / "text" / "README").write_text("hello")
    assert str(tmp_path / "text") in _raises(UnknownFormatError, tmp_path / "text")
    assert "no such" in _raises(MissingPathError, tmp_path / "nope")


def test_only_non_image_dicom_is_an_error(tmp_path):
    write_non_image(tmp_path / "sr" / "report.dcm")
    msg = _raises(SeriesError, tmp_path / "sr")
    assert str(tmp_path / "sr") in msg and "no DICOM images" in msg


@pytest.mark.parametrize("cut", ["pixels", "header"])
def test_truncated_file(tmp_path, cut):
    paths = write_series(tmp_path / "s", raw_stack(4), row_dir=ROW, col_dir=COL,
                         positions=stack_positions(ORIGIN, ROW, COL, np.arange(4)))
    data = paths[2].read_bytes()
    paths[2].write_bytes(data[:-100] if cut == "pixels" else data[:300])
    if cut == "pixels":  # the series' own file is broken: the series cannot load
        assert str(paths[2]) in _raises(CorruptDataError, tmp_path / "s")
        return
    # an unreadable header belongs to no known series: skipped with a note, the other slices load
    vol = volumen.load(tmp_path / "s")
    assert vol.shape == (3, 16, 20)
    assert [w for w in vol.meta["warnings"] if str(paths[2]) in w and "unreadable" in w]
    assert str(paths[2]) in _raises(CorruptDataError, paths[2])


def test_files_without_preamble_but_with_dicom_suffix(tmp_path):
    raw = raw_stack(3, seed=11)
    paths = write_series(tmp_path / "s", raw, row_dir=ROW, col_dir=COL, slope=1, intercept=-1024,
                         positions=stack_positions(ORIGIN, ROW, COL, np.arange(3)), shuffle_seed=None)
    for p in paths:  # rewrite as bare implicit-VR datasets (old ACR-NEMA style files)
        ds = pydicom.dcmread(p)
        del ds.file_meta
        ds.preamble = None
        pydicom.dcmwrite(p, ds, implicit_vr=True, little_endian=True)
        assert p.read_bytes()[128:132] != b"DICM"
    np.testing.assert_array_equal(volumen.load(tmp_path / "s").data, raw.astype(np.int32) - 1024)


def test_garbage_with_dicom_suffix(tmp_path):
    p = tmp_path / "x.dcm"
    p.write_bytes(b"\x00\x01garbage" * 5)
    assert str(p) in _raises(CorruptDataError, p)


def test_mixed_sizes_and_orientations(tmp_path):
    uid = new_uid("mixed")
    write_series(tmp_path / "m", raw_stack(3), row_dir=ROW, col_dir=COL, series_uid=uid, prefix="A",
                 positions=stack_positions(ORIGIN, ROW, COL, np.arange(3)))
    write_series(tmp_path / "m", raw_stack(2, rows=12), row_dir=ROW, col_dir=COL, series_uid=uid, prefix="B",
                 positions=stack_positions(ORIGIN, ROW, COL, 3 + np.arange(2)))
    msg = _raises(SeriesError, tmp_path / "m")
    assert str(tmp_path / "m") in msg and "image sizes" in msg
    uid = new_uid("mixed-orientation")
    write_series(tmp_path / "o", raw_stack(3), row_dir=ROW, col_dir=COL, series_uid=uid, prefix="A",
                 positions=stack_positions(ORIGIN, ROW, COL, np.arange(3)))
    write_series(tmp_path / "o", raw_stack(2), row_dir=[1, 0, 0], col_dir=[0, 1, 0], series_uid=uid, prefix="B",
                 positions=stack_positions(ORIGIN, [1, 0, 0], [0, 1, 0], 3 + np.arange(2)))
    msg = _raises(SeriesError, tmp_path / "o")
    assert str(tmp_path / "o") in msg and "orientations" in msg


def test_duplicate_positions_are_an_error(tmp_path):
    raw = raw_stack(5)
    offsets = np.array([0.0, 1.0, 2.0, 2.0, 3.0])
    paths = write_series(tmp_path / "d", raw, row_dir=ROW, col_dir=COL,
                         positions=stack_positions(ORIGIN, ROW, COL, offsets), shuffle_seed=None)
    msg = _raises(SeriesError, tmp_path / "d")
    assert str(paths[2]) in msg and str(paths[3]) in msg and "share a position" in msg


def test_compressed_without_decoder(tmp_path, monkeypatch):
    from pydicom.pixels import get_decoder

    missing = [ts for ts in (JPEGLSLossless, JPEGLosslessSV1, HTJ2KLossless) if not get_decoder(ts).is_available]
    ts = missing[0] if missing else JPEGLSLossless
    if not missing:  # every handler installed: pretend the JPEG-LS one is not
        class _Missing:
            is_available = False
        monkeypatch.setattr("pydicom.pixels.get_decoder", lambda uid: _Missing())
    paths = write_series(tmp_path / "c", raw_stack(3), row_dir=ROW, col_dir=COL, transfer_syntax=ts,
                         encapsulated=b"\xff\x4f garbage bytes \xff\xd9",
                         positions=stack_positions(ORIGIN, ROW, COL, np.arange(3)), shuffle_seed=None)
    msg = _raises(MissingDependencyError, tmp_path / "c")
    assert "pip install" in msg and ts.name in msg and any(str(p) in msg for p in paths)


def test_compressed_garbage_with_decoder_is_corrupt(tmp_path):
    from pydicom.pixels import get_decoder

    if not get_decoder(JPEG2000Lossless).is_available:
        pytest.skip("no JPEG 2000 decoder installed")
    paths = write_series(tmp_path / "c", raw_stack(1), row_dir=ROW, col_dir=COL, transfer_syntax=JPEG2000Lossless,
                         encapsulated=b"\x00garbage\x00", positions=ORIGIN[None])
    assert str(paths[0]) in _raises(CorruptDataError, paths[0])


def test_unknown_option_is_a_type_error(tmp_path):
    write_series(tmp_path / "s", raw_stack(2), row_dir=ROW, col_dir=COL,
                 positions=stack_positions(ORIGIN, ROW, COL, np.arange(2)))
    with pytest.raises(TypeError, match="colour"):
        _dicom.read(tmp_path / "s", colour=True)


# -- privacy --------------------------------------------------------------------------------------

def test_patient_identity_never_leaks(tmp_path):
    secrets = list(PATIENT.values()) + ["Doe", "Jane", "20240102"]
    write_series(tmp_path / "p" / "a", raw_stack(4), row_dir=ROW, col_dir=COL, patient=PATIENT,
                 positions=stack_positions(ORIGIN, ROW, COL, np.arange(4)), description="chest")
    write_non_image(tmp_path / "p" / "a" / "sr.dcm", patient=PATIENT)
    vol = volumen.load(tmp_path / "p" / "a")
    texts = [repr(vol), str(vol.meta), vol.name]
    write_series(tmp_path / "p" / "b", raw_stack(3), row_dir=ROW, col_dir=COL, patient=PATIENT,
                 positions=stack_positions(ORIGIN, ROW, COL, np.arange(3)), description="abdomen")
    with pytest.raises(MultipleSeriesError) as err:
        volumen.load(tmp_path / "p")
    texts.append(str(err.value))
    uid = new_uid("private-dup")
    write_series(tmp_path / "d", raw_stack(2), row_dir=ROW, col_dir=COL, patient=PATIENT, series_uid=uid,
                 positions=stack_positions(ORIGIN, ROW, COL, [0.0, 0.0]))
    with pytest.raises(SeriesError) as err:
        volumen.load(tmp_path / "d")
    texts.append(str(err.value))
    for text in texts:
        for secret in secrets:
            assert secret not in text, f"{secret!r} leaked into {text[:80]!r}"


@pytest.mark.parametrize("name", ["MR_small_bigendian.dcm", "MR_small_expb.dcm"])
def test_a_big_endian_file_renders_as_its_little_endian_twin(name):
    """pydicom's big-endian MR_small files hold the samples of MR_small.dcm in the other byte order: they load as
    the same native int16 volume and draw the same picture (rendering them failed with a Numba typing error)."""
    from pydicom.data import get_testdata_file

    from volumen.render import render_volume

    big, little = (volumen.load(get_testdata_file(f)) for f in (name, "MR_small.dcm"))
    assert big.data.dtype.isnative and np.array_equal(big.data, little.data)
    a, b = (render_volume(v, size=(32, 32)).rgba for v in (big, little))
    assert a[..., 3].max() > 0.1 and np.array_equal(a, b)
