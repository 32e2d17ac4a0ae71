"""File > Open from archive... against the test Orthanc, offscreen: search, series with thumbnails, retrieve with a
progress bar (and a cancel that keeps what came), and the volume opens with the uploaded voxels."""

from __future__ import annotations

import numpy as np
import pydicom

import volumen
import volumen.pacs as pacs


def _search(qtbot, dlg, **fields):
    for key, edit in dlg.fields.items():
        edit.setText(fields.get(key, ""))
    dlg.search()
    qtbot.waitUntil(lambda: dlg.status.text().endswith("found") or "server" in dlg.status.text(), timeout=30000)


def test_search_browse_retrieve_and_open(make_window, qtbot, archive, archive_config, monkeypatch):
    win = make_window()
    dlg = win.open_archive_dialog()
    assert dlg.isVisible() and dlg.server.currentText() == "archive"
    _search(qtbot, dlg, patient_name="Doe*", modality="CT", date_from="20240101")
    expected = archive.server.find_studies({"PatientName": "Doe*", "ModalitiesInStudy": "CT", "StudyDate": "20240101-"})
    assert {s.uid for s in dlg.studies} == expected and dlg.results.rowCount() == len(expected)
    row = [s.uid for s in dlg.studies].index(archive.ct.study_uid)
    assert [dlg.results.item(row, c).text() for c in range(3)] == ["20240102", "Doe^Jane", "PAT-001"]

    dlg.choose_study(row)
    qtbot.waitUntil(lambda: dlg.series_list.count() == 2, timeout=30000)
    assert [dlg.series_list.item(i).toolTip() for i in range(2)] == [s.series_uid for s in archive.series["chest"]]
    thumb = dlg.thumbnails[archive.ct.series_uid]
    slices = [pydicom.dcmread(p).pixel_array for p in archive.ct.folder.iterdir()]
    assert thumb.shape == (24, 20)  # rows x columns of the series, under the 64-pixel side
    assert any(np.array_equal(thumb, pacs._thumbnail.window_to_uint8(s, 40, 400)) for s in slices)  # its window
    assert not dlg.series_list.item(0).icon().isNull()

    # a cancel in the middle: no volume opens, what came stays for the next retrieve
    write, calls = pacs.SeriesCache.write, []

    def write_then_cancel(self, ds):
        calls.append(write(self, ds))
        if len(calls) == 3:
            dlg.cancel()
        return calls[-1]

    monkeypatch.setattr(pacs.SeriesCache, "write", write_then_cancel)
    dlg.choose_series(0)
    dlg.retrieve()
    qtbot.waitUntil(lambda: "cancelled" in dlg.status.text(), timeout=30000)
    assert "cancelled after 3 of 8" in dlg.status.text() and win.state.scene.volume_ref == "phantom:head?size=64"
    monkeypatch.setattr(pacs.SeriesCache, "write", write)

    dlg.retrieve()
    ref = pacs.make_ref("archive", archive.ct.study_uid, archive.ct.series_uid)
    qtbot.waitUntil(lambda: win.state.scene.volume_ref == ref, timeout=60000)
    assert dlg.progress.value() == 100 and win.last_error is None
    vol, truth = win.state.volume, volumen.load(archive.ct.folder)
    assert np.array_equal(np.asarray(vol.data), np.asarray(truth.data))
    np.testing.assert_allclose(vol.affine, truth.affine, atol=1e-6)
    assert ref in win.recent.items
    from volumen.app._session import resolve_volume

    assert np.array_equal(np.asarray(resolve_volume(ref).data), np.asarray(truth.data))  # sessions, `volumen view`
    assert win.wait_for_final(120) and win.view3d.frame is not None
    dlg.close()


def test_archive_errors_are_one_line_in_the_dialog(make_window, qtbot, archive, archive_config, monkeypatch):
    from tests.pacs.archive_data import PASSWORD_ENV
    from tests.pacs.orthanc_server import PASSWORD

    monkeypatch.setenv(PASSWORD_ENV, "wrong-password-123")
    win = make_window(load=False)
    dlg = win.open_archive_dialog()
    _search(qtbot, dlg, patient_name="Doe*")
    text = dlg.status.text()
    assert text.startswith("server archive (") and "HTTP 401" in text and "\n" not in text
    assert "wrong-password-123" not in text and PASSWORD not in text and dlg.results.rowCount() == 0
    dlg.close()


def test_a_password_not_configured_is_asked_for_once(make_window, qtbot, archive, archive_config, monkeypatch):
    """servers.toml names a user without a password: the dialog asks (on the GUI thread, before the request runs on
    its worker) and the answer serves the search and the series listing after it."""
    from PySide6.QtWidgets import QInputDialog

    from tests.pacs.orthanc_server import PASSWORD

    archive_config.write_text("\n".join(line for line in archive_config.read_text().splitlines()
                                        if not line.startswith("password_env")))
    monkeypatch.setattr(pacs._credentials, "_asked", {})
    asked = []

    def get_text(parent, title, label, mode):
        asked.append(label)
        return PASSWORD, True

    monkeypatch.setattr(QInputDialog, "getText", get_text)
    win = make_window(load=False)
    dlg = win.open_archive_dialog()
    _search(qtbot, dlg, patient_id="PAT-001")
    assert [s.uid for s in dlg.studies] == [archive.ct.study_uid]
    dlg.choose_study(0)
    qtbot.waitUntil(lambda: dlg.series_list.count() == 2, timeout=30000)
    assert asked == [f"password of alice on archive ({archive.server.dicomweb_url}):"]
    dlg.close()
