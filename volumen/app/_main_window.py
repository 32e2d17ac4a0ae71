"""The main window: four linked views, the panels, menus, and the render scheduling.

Layout: axial (top left), coronal (top right), sagittal (bottom left) and the
3D view (bottom right); panels in tabs on the right (render, transfer
function, lights, clipping, segmentation, endoscopy). Keys: J adds a light at
the camera, L cycles the shading models, W/A/S/D/R/F and the arrows fly in
endoscopy.

Rendering: every change of the picture's settings asks the worker for a new
frame (coalesced on the next event-loop turn); while the user drags, frames
come at a reduced viewport and the full picture follows 150 ms after the last
change. :meth:`MainWindow.wait_for_final` waits for the refined picture.
"""

from __future__ import annotations

import time

import numpy as np
from PySide6.QtCore import QCoreApplication, Qt, QTimer
from PySide6.QtWidgets import (
    QComboBox,
    QDockWidget,
    QFileDialog,
    QGridLayout,
    QInputDialog,
    QMainWindow,
    QTabWidget,
    QToolBar,
    QWidget,
)

from ..core import VIEWS, WINDOW_PRESETS, default_camera
from ._clip_panel import ClipPanel
from ._endo_panel import EndoscopyPanel
from ._labels_panel import LabelsPanel
from ._light_panel import LightPanel, add_light_at_camera
from ._measure_menu import build_measure_menu
from ._recent import RecentFiles
from ._render_panel import RenderPanel, cycle_shading
from ._segment_panel import SegmentPanel
from ._slice_view import SliceView
from ._state import PICTURE_TOPICS, AppState
from ._tasks import run_task, show_error
from ._tf_editor import TransferFunctionEditor
from ._view3d import View3D
from ._view_picture import FrameJob
from ._worker import RenderWorker

__all__ = ["MainWindow"]


class MainWindow(QMainWindow):
    """The application window. ``recent`` defaults to the user's recent-files list."""

    def __init__(self, *, recent: RecentFiles | None = None, refine_ms: int = 150):
        super().__init__()
        self.setWindowTitle("volumen")
        self.state = st = AppState()
        self.recent = recent if recent is not None else RecentFiles()
        self.worker = RenderWorker(self)
        self.worker.frame_ready.connect(self._frame)
        self.worker.failed.connect(self._render_failed)
        self.worker.raster_status.connect(self._raster_status)
        self.worker.start()
        self.token = 0
        self.final_token = -1
        self.last_error = None
        #: which device the 3-D view ray casts on and why (None until the worker has probed OpenGL)
        self.device_reason: str | None = None
        self.endoscopy = None
        self._loading = None
        self.series_chooser = None  # the open series chooser, if any
        self.archive_dialog = None  # File > Open from archive..., once opened

        self.slices = {p: SliceView(st, p) for p in ("axial", "coronal", "sagittal")}
        self.view3d = View3D(st)
        for v in self.slices.values():
            v.picked.connect(self._picked)
        self.view3d.interaction_finished.connect(lambda: self.request_render(final=True))
        self.view3d.fly_turn.connect(lambda y, p: self.endo_panel.turn(y, p))
        grid = QGridLayout()
        grid.setSpacing(2)
        grid.setContentsMargins(0, 0, 0, 0)
        grid.addWidget(self.slices["axial"], 0, 0)
        grid.addWidget(self.slices["coronal"], 0, 1)
        grid.addWidget(self.slices["sagittal"], 1, 0)
        grid.addWidget(self.view3d, 1, 1)
        for i in range(2):
            grid.setRowStretch(i, 1)
            grid.setColumnStretch(i, 1)
        central = QWidget()
        central.setLayout(grid)
        self.setCentralWidget(central)

        self.render_panel = RenderPanel(st)
        self.tf_editor = TransferFunctionEditor(st)
        self.light_panel = LightPanel(st)
        self.clip_panel = ClipPanel(st)
        self.segment_panel = SegmentPanel(st, self)
        self.endo_panel = EndoscopyPanel(st, self)
        self.labels_panel = LabelsPanel(st, self)
        tabs = QTabWidget()
        for w, name in ((self.render_panel, "Render"), (self.tf_editor, "Transfer"), (self.light_panel, "Lights"),
                        (self.clip_panel, "Clipping"), (self.segment_panel, "Segment"),
                        (self.labels_panel, "Structures"), (self.endo_panel, "Endoscopy")):
            tabs.addTab(w, name)
        self.tabs = tabs
        dock = QDockWidget("Controls", self)
        dock.setWidget(tabs)
        dock.setFeatures(QDockWidget.DockWidgetMovable | QDockWidget.DockWidgetFloatable)
        self.addDockWidget(Qt.RightDockWidgetArea, dock)
        self._build_actions()

        self._schedule = QTimer(self, singleShot=True, interval=0)
        self._schedule.timeout.connect(self._submit)
        self._refine = QTimer(self, singleShot=True, interval=refine_ms)
        self._refine.timeout.connect(lambda: self.request_render(final=True))
        self._final_wanted = False
        for topic in PICTURE_TOPICS:
            st.subscribe(topic, self.request_render)
        self.resize(1100, 760)

    # -- menus and toolbar ----------------------------------------------------
    def _build_actions(self) -> None:
        from ._screenshot import save_widget

        m = self.menuBar().addMenu("&File")
        m.addAction("Open file...", self.open_dialog)
        m.addAction("Open DICOM folder...", lambda: self.open_dialog(folder=True))
        m.addAction("Open from archive...", self.open_archive_dialog)
        self.recent_menu = m.addMenu("Recent files")
        self._fill_recent()
        m.addSeparator()
        m.addAction("Load session...", self._load_session_dialog)
        m.addAction("Save session...", self._save_session_dialog)
        m.addSeparator()
        m.addAction("Screenshot of the window...", lambda: self._save_dialog(lambda p: save_widget(self, p)))
        m.addAction("Screenshot of the 3D view...", self._screenshot_3d_dialog)
        m.addSeparator()
        m.addAction("Quit", self.close)
        build_measure_menu(self)
        tb = QToolBar("Views")
        self.addToolBar(tb)
        for view in VIEWS:
            tb.addAction(view.capitalize(), lambda v=view: self.set_view(v))
        self.window_presets = QComboBox()
        self.window_presets.addItem("Window preset")
        self.window_presets.addItems(list(WINDOW_PRESETS))
        self.window_presets.activated.connect(
            lambda i: self.state.set_window(WINDOW_PRESETS[self.window_presets.itemText(i)]) if i > 0 else None)
        tb.addWidget(self.window_presets)

    def _fill_recent(self) -> None:
        self.recent_menu.clear()
        for path in self.recent.items:
            self.recent_menu.addAction(path, lambda p=path: self.open_path(p))
        self.recent_menu.setEnabled(bool(self.recent.items))

    def set_view(self, view: str) -> None:
        """One of the six anatomical views (``volumen.core.VIEWS``)."""
        if self.state.volume is not None:
            self.state.set_camera(default_camera(self.state.volume, view=view))

    # -- errors ---------------------------------------------------------------
    def report_error(self, title: str, message: str):
        """Show an error in a dialog that does not block; the message is kept in ``last_error``."""
        self.last_error = (title, message)
        self.statusBar().showMessage(f"{title}: {message.splitlines()[0] if message else ''}", 10000)
        return show_error(self, title, message)

    def _render_failed(self, token: int, message: str) -> None:
        if token == self.token:
            self.final_token = token  # nothing more will come for this request
        self.report_error("Rendering failed", message)

    def _raster_status(self, ok: bool, found: str) -> None:
        """OpenGL found (``found``: its renderer) or not (``found``: why) by the worker. The 3-D view ray casts on
        the fastest device here, as ``auto`` does (``render.choose_device``): ``gl`` on a hardware renderer, the
        CPU when OpenGL is missing or a software rasterizer (llvmpipe, SwiftShader); the status bar and
        :attr:`device_reason` say which and why."""
        from ..render.raster import is_software_renderer

        self.render_panel.set_raster_available(ok, "" if ok else found)
        self.segment_panel.set_raster_available(ok, "" if ok else found)
        st = self.state
        if ok and not is_software_renderer(found):
            self.device_reason = f"3-D view: OpenGL ray casting on {found} (a hardware renderer)"
            if st.device == "cpu" and st.technique.name == "raycast":
                st.set_display(device="gl")
        else:
            self.device_reason = (f"3-D view on the CPU: OpenGL is {found}, a software renderer slower than the CPU "
                                  f"ray caster" if ok else f"3-D view on the CPU: {found}")
            if st.device == "gl" and st.technique.name == "raycast":
                st.set_display(device="cpu")
        self.statusBar().showMessage(self.device_reason, 15000)

    # -- data -----------------------------------------------------------------
    def set_volume(self, volume, ref: str) -> None:
        """Show ``volume`` (named ``ref`` in sessions)."""
        self.state.set_volume(volume, ref)
        self.setWindowTitle(f"volumen - {volume.name or ref}")
        self.load_warnings = list(volume.meta.get("warnings", []))  # the reader's, said as the CLI says them
        if self.load_warnings:
            more = f" ({len(self.load_warnings)} in all)" if len(self.load_warnings) > 1 else ""
            self.statusBar().showMessage(f"Warning: {self.load_warnings[0]}{more}", 15000)

    def open_dialog(self, folder: bool = False) -> None:
        if folder:
            path = QFileDialog.getExistingDirectory(self, "Open a DICOM folder")
        else:
            path, _ = QFileDialog.getOpenFileName(self, "Open a volume", "", "Volumes (*.nii *.nii.gz *.nrrd *.nhdr "
                                                  "*.mha *.mhd *.vtk *.npy *.npz *.dcm);;All files (*)")
        if path:
            self.open_path(path)

    def open_path(self, path: str, series: str | None = None):
        """Load ``path`` in the background (progress dialog); on failure an error dialog, the old data stays.

        A DICOM folder holding several series opens the series chooser (``self.series_chooser``);
        the chosen one (``series``, a SeriesInstanceUID) is then loaded.
        """
        from ._session import load_or_list, series_ref

        ref = series_ref(path, series)

        def done(result):
            if isinstance(result, tuple):  # several series: (summaries, notes)
                self._choose_series(path, *result)
                return
            self.set_volume(result, ref)
            if not str(path).startswith("phantom:"):
                self.recent.add(ref)
                self._fill_recent()

        def bad(exc):
            self.report_error("Cannot open the data", str(exc))

        self._loading = run_task(self, lambda: load_or_list(ref), done, bad, label=f"Loading {path}...")
        return self._loading

    def open_archive_dialog(self):
        """File > Open from archive...: search a PACS and open a retrieved series (non-blocking dialog)."""
        from ._archive_dialog import ArchiveDialog

        if self.archive_dialog is None:
            self.archive_dialog = ArchiveDialog(self)
            self.archive_dialog.retrieved.connect(self.open_path)
        self.archive_dialog.open()
        return self.archive_dialog

    def _choose_series(self, path: str, series: list, notes: list[str]) -> None:
        from ._series_chooser import ask_series

        self.series_chooser = ask_series(self, str(path), series, lambda uid: self.open_path(path, series=uid), notes)

    # -- sessions -------------------------------------------------------------
    def session(self) -> dict:
        """The current session as a dict (see ``volumen.app._session``)."""
        from ._session import session_dict

        endo = self.endoscopy.to_dict() if self.endoscopy is not None else None
        return session_dict(self.state, self.view3d.view_size, endo)

    def save_session(self, path) -> None:
        from ._session import save_session

        try:
            save_session(path, self.session())
        except Exception as exc:  # noqa: BLE001 - reported, never a crash
            self.report_error("Cannot save the session", str(exc))

    def load_session(self, path, volume=None) -> bool:
        """Load a session file (synchronously); ``volume`` skips reading the data again. False on failure."""
        from ._endo_model import Endoscopy
        from ._session import apply_session, load_session, resolve_volume

        try:
            d = load_session(path)
            vol = volume if volume is not None else resolve_volume(d["scene"]["volume"])
            endo = apply_session(self.state, d, vol)
        except Exception as exc:  # noqa: BLE001 - reported, the previous state stays usable
            self.report_error("Cannot load the session", str(exc))
            return False
        if endo:
            self.endo_panel.model = Endoscopy.from_dict(vol, endo)
            self.endo_panel._publish()
        return True

    def _load_session_dialog(self) -> None:
        path, _ = QFileDialog.getOpenFileName(self, "Load a session", "", "Sessions (*.json)")
        if path:
            self.load_session(path)

    def _save_session_dialog(self) -> None:
        path, _ = QFileDialog.getSaveFileName(self, "Save the session", "session.json", "Sessions (*.json)")
        if path:
            self.save_session(path)

    def _save_dialog(self, save) -> None:
        path, _ = QFileDialog.getSaveFileName(self, "Save a picture", "screenshot.png", "PNG (*.png)")
        if path:
            try:
                save(path)
            except Exception as exc:  # noqa: BLE001 - any failure is reported in a dialog, the window stays
                self.report_error("Cannot save the picture", str(exc))

    def _screenshot_3d_dialog(self) -> None:
        w, h = self.view3d.view_size
        text, ok = QInputDialog.getText(self, "3D screenshot", "Size (WIDTHxHEIGHT):", text=f"{w * 2}x{h * 2}")
        if not ok:
            return
        path, _ = QFileDialog.getSaveFileName(self, "Save the 3D view", "view3d.png", "PNG (*.png)")
        if path:
            try:
                size = tuple(int(v) for v in text.lower().split("x"))
                self.screenshot_3d(path, size)
            except Exception as exc:  # noqa: BLE001 - any failure is reported in a dialog, the window stays
                self.report_error("Cannot make the screenshot", str(exc))

    def screenshot_3d(self, path, size: tuple[int, int]):
        """Render the 3D view at ``size`` in the background and save it; returns the task."""
        from ._screenshot import render_view_picture, save_rgb

        job = self.frame_job()
        return run_task(self, lambda: save_rgb(render_view_picture(job, size), path),
                        lambda p: self.statusBar().showMessage(f"Wrote {p}", 5000),
                        lambda e: self.report_error("Cannot make the screenshot", str(e)),
                        label="Rendering the screenshot...")

    # -- rendering ------------------------------------------------------------
    def frame_job(self) -> FrameJob:
        """What the 3D view shows now."""
        st = self.state
        return FrameJob(scene=st.scene, camera=st.camera, size=self.view3d.view_size, device=st.device,
                        technique=st.technique,
                        brightness=st.brightness, background=st.background, stereo=st.stereo,
                        mesh=st.mesh, mesh_display=st.mesh_display, token=self.token)

    def request_render(self, final: bool = False) -> None:
        """Ask for a new picture on the next event-loop turn (``final``: the full one, not reduced)."""
        if self.state.volume is None or self.state.camera is None:
            return
        self._final_wanted = self._final_wanted or final or not self.state.interacting
        self._schedule.start()

    def _submit(self) -> None:
        self.token += 1
        interactive = not self._final_wanted
        self._final_wanted = False
        self.worker.submit(self.frame_job(), interactive=interactive)
        if interactive:
            self._refine.start()

    def _frame(self, frame) -> None:
        shown = self.view3d.frame
        if shown is not None and frame.token < shown.token:
            return  # a late frame of an older request
        self.view3d.show_frame(frame)
        if frame.final:
            self.final_token = max(self.final_token, frame.token)
            self.statusBar().showMessage(f"frame {frame.seconds * 1000:.0f} ms", 3000)

    def resizeEvent(self, event) -> None:  # noqa: N802 - Qt names the override
        super().resizeEvent(event)
        self.request_render(final=True)

    def wait_for_final(self, timeout: float = 60.0) -> bool:
        """Process events until the refined picture of the newest request is shown (or ``timeout`` s)."""
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            QCoreApplication.processEvents()
            loading = self._loading is not None and not self._loading.finished
            if (not loading and not self._schedule.isActive() and not self._refine.isActive()
                    and self.final_token >= self.token and self.worker.idle):
                QCoreApplication.processEvents()
                return True
            time.sleep(0.005)
        return False

    # -- picking, endoscopy, keys ---------------------------------------------
    def set_pick_mode(self, mode: str | None) -> None:
        """Slice clicks pick ``"seed"``, ``"endo-start"``, ``"endo-end"``, or move the crosshair (None)."""
        for v in self.slices.values():
            v.pick_mode = mode
            v.setCursor(Qt.CrossCursor if mode else Qt.ArrowCursor)

    def _picked(self, mode: str, world) -> None:
        if mode == "seed":
            self.state.add_seed(world)
        elif mode in ("endo-start", "endo-end"):
            self.endo_panel.pick(mode, np.asarray(world, float))
            self.set_pick_mode(None)

    def set_endoscopy(self, model) -> None:
        self.endoscopy = model
        for v in self.slices.values():
            v.endoscopy = model
        self.view3d.centerline = None if model is None else model.centerline
        self.view3d.update()

    def set_flying(self, on: bool) -> None:
        self.view3d.flying = on
        self.view3d.status_text = "endoscopy: W/S A/D R/F, arrows" if on else ""
        if on:
            self.view3d.setFocus()

    def keyPressEvent(self, event) -> None:  # noqa: N802 - Qt names the override
        key = event.key()
        name = QKEYS.get(key)
        if name and self.endo_panel.key(name):
            return
        if key == Qt.Key_J and self.state.camera is not None:
            add_light_at_camera(self.state)
        elif key == Qt.Key_L and self.state.volume is not None:
            mode = cycle_shading(self.state)
            self.statusBar().showMessage(f"shading: {mode}", 3000)
        else:
            super().keyPressEvent(event)

    def closeEvent(self, event) -> None:  # noqa: N802 - Qt names the override
        self.endo_panel.timer.stop()
        self.worker.stop(timeout=30.0)
        super().closeEvent(event)


QKEYS = {Qt.Key_W: "W", Qt.Key_S: "S", Qt.Key_A: "A", Qt.Key_D: "D", Qt.Key_R: "R", Qt.Key_F: "F",
         Qt.Key_Left: "Left", Qt.Key_Right: "Right", Qt.Key_Up: "Up", Qt.Key_Down: "Down"}
