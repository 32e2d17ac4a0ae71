"""Opening DICOM in the application: the series chooser for a folder of several series (one file corrupt),
and an error dialog for a corrupt file that leaves the loaded volume and the session as they were."""

from __future__ import annotations

import pydicom
import pytest
from pydicom.data import get_testdata_file
from PySide6.QtWidgets import QApplication, QMessageBox

UIDS = ("1.2.826.0.1.3680043.8.498.11", "1.2.826.0.1.3680043.8.498.12")


def _folder_with_two_series_and_a_corrupt_file(folder):
    """pydicom's CT_small.dcm copied into series 1 (3 slices, 2 mm) and series 2 (5 slices, 1 mm), plus junk."""
    folder.mkdir()
    for number, (uid, n, gap) in enumerate(zip(UIDS, (3, 5), (2.0, 1.0), strict=True), start=1):
        for k in range(n):
            ds = pydicom.dcmread(get_testdata_file("CT_small.dcm"))
            ds.SeriesInstanceUID, ds.SeriesNumber, ds.SOPInstanceUID = uid, number, f"{uid}.{k + 1}"
            ds.SeriesDescription = f"series {number}"
            ds.ImagePositionPatient = [0.0, 0.0, gap * k]
            ds.save_as(folder / f"s{number}_{k}.dcm")
    (folder / "corrupt.dcm").write_bytes(b"\x00" * 132 + b"garbage")
    return folder


def _close_boxes():
    for w in QApplication.topLevelWidgets():
        if isinstance(w, QMessageBox) and w.isVisible():
            w.close()


def test_view_on_a_folder_of_two_series_offers_the_chooser_and_loads_the_choice(qtbot, tmp_path, monkeypatch):
    """What ``volumen view FOLDER`` runs (create_window without waiting), driven offscreen."""
    from volumen.app import create_window

    monkeypatch.setenv("VOLUMEN_CONFIG_DIR", str(tmp_path / "config"))
    folder = _folder_with_two_series_and_a_corrupt_file(tmp_path / "dicom")
    win = create_window(str(folder))
    qtbot.addWidget(win)
    qtbot.waitUntil(lambda: win.series_chooser is not None and win.series_chooser.isVisible(), timeout=20000)
    chooser = win.series_chooser
    assert [(s.number, s.size, s.files) for s in chooser.series] == [("1", (128, 128, 3), 3), ("2", (128, 128, 5), 5)]
    assert "1 file(s) were skipped" in chooser.label.text()
    chooser.choose(1)
    chooser.accept()
    qtbot.waitUntil(lambda: win.state.volume is not None, timeout=20000)
    vol = win.state.volume
    assert vol.shape == (5, 128, 128) and vol.meta["series_uid"] == UIDS[1]
    assert vol.spacing[0] == pytest.approx(1.0, abs=1e-6)
    assert win.state.scene.volume_ref == f"{folder}?series={UIDS[1]}"
    assert [w for w in vol.meta["warnings"] if "corrupt.dcm" in w]
    assert win.wait_for_final(120) and win.last_error is None, win.last_error
    win.close()


def test_corrupt_dicom_file_shows_an_error_and_keeps_volume_and_session(make_window, qtbot, tmp_path):
    win = make_window()
    volume, scene, camera = win.state.volume, win.state.scene, win.state.camera
    bad = tmp_path / "broken.dcm"
    data = bytearray(pydicom.dcmread(get_testdata_file("CT_small.dcm")).PixelData)
    ds = pydicom.dcmread(get_testdata_file("CT_small.dcm"))
    ds.PixelData = bytes(data[: len(data) // 2])  # half the pixels: undecodable
    ds.save_as(bad)
    task = win.open_path(str(bad))
    qtbot.waitUntil(lambda: task.finished, timeout=20000)
    assert win.last_error is not None and "broken.dcm" in win.last_error[1]
    boxes = [w for w in QApplication.topLevelWidgets() if isinstance(w, QMessageBox) and w.isVisible()]
    assert boxes and "broken.dcm" in boxes[-1].text()
    _close_boxes()
    assert win.state.volume is volume and win.state.scene == scene and win.state.camera == camera
    assert win.view3d.frame is not None


def test_series_reference_round_trips_through_resolve_volume(tmp_path):
    """Sessions and recent files name a chosen series as ``FOLDER?series=UID``."""
    from volumen.app._session import resolve_volume, series_ref, split_series_ref

    folder = _folder_with_two_series_and_a_corrupt_file(tmp_path / "d")
    ref = series_ref(str(folder), UIDS[0])
    assert split_series_ref(ref) == (str(folder), UIDS[0]) and series_ref(str(folder), None) == str(folder)
    vol = resolve_volume(ref)
    assert vol.shape == (3, 128, 128) and vol.meta["series_uid"] == UIDS[0]
    odd = tmp_path / "odd?series=x"  # a real path that looks like a reference is never split
    odd.mkdir()
    assert split_series_ref(str(odd)) == (str(odd), None)


def test_a_single_slice_opens_face_on_as_its_mip_and_a_volume_composited(make_window, head64):
    """A single slice (pydicom's CT_small.dcm) opens as the command line draws it: from the feet, as its MIP
    (the mode box says so), the slice bright in the 3-D view; the next whole volume is composited again."""

    import volumen

    win = make_window()
    win.state.update_scene(mode="isosurface")
    one = volumen.load(get_testdata_file("CT_small.dcm"))
    win.set_volume(one, "CT_small.dcm")
    assert win.wait_for_final(60) and win.last_error is None, win.last_error
    state = win.state
    assert state.scene.mode == "mip" and win.render_panel.mode.currentData() == "mip"
    assert state.camera.position[2] < one.center[2]  # from the feet
    rgb = win.view3d.frame.rgb.astype(int).sum(axis=2)
    print(f"lit {(rgb > 30).mean():.2f} of the view, brightest {rgb.max() / 3:.0f}")
    assert (rgb > 30).mean() > 0.2 and rgb.max() > 3 * 200
    win.set_volume(head64, "phantom:head?size=64")
    assert win.wait_for_final(60) and state.scene.mode == "composite"
