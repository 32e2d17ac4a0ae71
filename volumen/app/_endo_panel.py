"""The endoscopy panel: path between two picked points, manual and guided flight, playback, video.

* pick the start and the end in the slice views, compute the lumen (air or
  contrast, found from the data, or read from a segmentation file) and its
  centerline, as ``volumen fly`` does (a lumen that leaks is refused with the
  same one-line message); the lumen shows as an overlay in the slice views (so a
  leak shows), the centerline in the slice views and the 3D view; flight and
  recording draw the lumen's own wall (the data held to the lumen);
* the lumen's diameter along the path under the flight, with the current cross-section's numbers
  (:class:`~volumen.app._endo_profile.ProfileView`);
* save the curved planar reformation (straightened or stretched) along the
  centerline, its cross-sections marked, as a PNG;
* manual flight: W/S forward/back, A/D sideways, R/F up/down, arrow keys or
  left drag to turn; collisions keep the eye in the lumen and a red
  "blocked" marker flashes when a move hits the wall;
* guided flight advances along the centerline while the user steers;
* the automatic path plays forward or backward, and is recorded to a video
  (MP4 or GIF) in the background.

The camera's position is drawn in the slice views while flying.
"""

from __future__ import annotations

from PySide6.QtCore import QTimer
from PySide6.QtWidgets import (
    QComboBox,
    QFileDialog,
    QFormLayout,
    QGridLayout,
    QLabel,
    QPushButton,
    QVBoxLayout,
    QWidget,
)

from ._endo_model import LUMENS, Endoscopy
from ._endo_profile import ProfileView
from ._tasks import run_task

__all__ = ["EndoscopyPanel", "FLY_KEYS"]

#: key name -> (right, up, forward) unit move, or ("turn", yaw, pitch) degrees
FLY_KEYS = {"W": (0, 0, 1), "S": (0, 0, -1), "A": (-1, 0, 0), "D": (1, 0, 0), "R": (0, 1, 0), "F": (0, -1, 0),
            "Left": ("turn", 5, 0), "Right": ("turn", -5, 0), "Up": ("turn", 0, 5), "Down": ("turn", 0, -5)}


class EndoscopyPanel(QWidget):
    """Drives an :class:`~volumen.app._endo_model.Endoscopy` from the main window."""

    def __init__(self, state, window, parent=None):
        super().__init__(parent)
        self.state = state
        self.window = window
        self.model: Endoscopy | None = None
        self.step_mm = 2.0
        self._saved_scene = None
        self._poses: list = []
        self.lumen = QComboBox()
        self.lumen.addItems(list(LUMENS))
        self.status = QLabel("Pick a start and an end point.")
        self.status.setWordWrap(True)
        b = {}
        for key, label in (("start", "Pick start"), ("end", "Pick end"), ("compute", "Compute centerline"),
                           ("fly", "Fly (manual)"), ("guided", "Guided"), ("forward", "Play forward"),
                           ("backward", "Play backward"), ("stop", "Stop"), ("record", "Record video..."),
                           ("mask", "Lumen mask..."), ("cpr", "Save CPR...")):
            b[key] = QPushButton(label)
        self.buttons = b
        b["start"].clicked.connect(lambda: window.set_pick_mode("endo-start"))
        b["end"].clicked.connect(lambda: window.set_pick_mode("endo-end"))
        b["compute"].clicked.connect(self.compute)
        b["fly"].clicked.connect(self.start_manual)
        b["guided"].clicked.connect(self.start_guided)
        b["forward"].clicked.connect(lambda: self.play(reverse=False))
        b["backward"].clicked.connect(lambda: self.play(reverse=True))
        b["stop"].clicked.connect(self.stop)
        b["record"].clicked.connect(self._record)
        b["mask"].clicked.connect(self._choose_mask)
        b["cpr"].clicked.connect(self._save_cpr)
        self.cpr_kind = QComboBox()
        self.cpr_kind.addItems(["straightened", "stretched"])
        form = QFormLayout()
        form.addRow("Lumen", self.lumen)
        form.addRow("CPR", self.cpr_kind)
        grid = QGridLayout()
        for n, key in enumerate(b):
            grid.addWidget(b[key], n // 2, n % 2)
        lay = QVBoxLayout(self)
        lay.addLayout(form)
        lay.addLayout(grid)
        lay.addWidget(self.status)
        self.profile_view = ProfileView()
        lay.addWidget(self.profile_view)
        lay.addWidget(QLabel("Flight: W/S forward/back, A/D sideways, R/F up/down,\narrows or left drag turn."))
        lay.addStretch(1)
        self.timer = QTimer(self, interval=100)
        self.timer.timeout.connect(self._tick)
        state.subscribe("volume", self.reset)
        self.reset()

    # -- model ----------------------------------------------------------------
    def reset(self) -> None:
        """A new volume: forget the path."""
        self.stop()
        v = self.state.volume
        self.model = None if v is None else Endoscopy(v, lumen=self.lumen.currentText())
        self.profile_view.set_profile(None)
        self._publish()

    def _publish(self) -> None:
        self.window.set_endoscopy(self.model)
        m = self.model
        has_path = m is not None and m.centerline is not None
        for k in ("guided", "forward", "backward", "record", "cpr"):
            self.buttons[k].setEnabled(has_path)
        self.buttons["fly"].setEnabled(m is not None and m.start is not None)
        self.state.emit("endoscopy")

    def pick(self, which: str, world) -> None:
        """Set the start (``"endo-start"``) or end (``"endo-end"``) point."""
        if self.model is None:
            return
        if which == "endo-start":
            self.model.start = world
        else:
            self.model.end = world
        self.model.centerline = None
        self.status.setText("Start and end set: compute the centerline." if self.model.end is not None
                            and self.model.start is not None else "Now pick the other point.")
        self._publish()

    def compute(self):
        """Compute the centerline in the background; returns the task (or None)."""
        m = self.model
        if m is None:
            return None
        m.lumen = self.lumen.currentText()

        def done(cl):
            import numpy as np

            from volumen.core import values_of

            said = m.estimate.describe(**values_of(self.state.volume))
            self.status.setText(f"{said}. Centerline: {cl.length:.1f} mm, {len(cl.points)} points.")
            self.state.set_mask(self.state.volume.with_data(m.mask.astype(np.uint8)))  # the slices' overlay
            self.profile_view.set_profile(m.profile)
            self._publish()

        def bad(exc):
            self.window.report_error("No centerline", str(exc))

        return run_task(self.window, m.compute, done, bad, label="Computing the centerline...")

    # -- flight ---------------------------------------------------------------
    def _enter_flight(self) -> None:
        from dataclasses import replace

        if self._saved_scene is None:
            self._saved_scene = (self.state.scene, self.state.camera)
        self.state.update_scene(volume=self.model.drawn_volume(), transfer=self.model.transfer(), mode="composite",
                                shading=replace(self.state.scene.shading, mode="headlight"),
                                clipping=replace(self.state.scene.clipping, crop=None, planes=()))
        self.window.set_flying(True)
        self._show_pose()

    def start_manual(self) -> None:
        try:
            self.model.start_manual(self.model.pose)
        except ValueError as exc:
            self.window.report_error("Cannot fly", str(exc))
            return
        self.timer.stop()
        self._enter_flight()

    def start_guided(self) -> None:
        self.model.start_guided()
        self._enter_flight()
        self._poses = []
        self.timer.start()

    def play(self, reverse: bool = False) -> None:
        """Play the automatic path (10 frames per second)."""
        self.model.start_guided()
        self._poses = self.model.path().play(fps=10, reverse=reverse)
        self._enter_flight()
        self.timer.start()

    def stop(self) -> None:
        """Leave flight and restore the scene and camera from before it."""
        self.timer.stop()
        self._poses = []
        if self.model is not None:
            self.model.stop()
        if self._saved_scene is not None:
            scene, cam = self._saved_scene
            self._saved_scene = None
            self.state.update_scene(volume=scene.volume, transfer=scene.transfer, mode=scene.mode,
                                    shading=scene.shading, clipping=scene.clipping)
            self.state.set_camera(cam)
        if hasattr(self.window, "set_flying"):
            self.window.set_flying(False)

    def _tick(self) -> None:
        m = self.model
        if self._poses:
            pose = self._poses.pop(0)
            self.state.set_camera(pose.camera(fov=m.fov, near=0.5 * m.margin))
            self.profile_view.set_eye(pose.position)
            if not self._poses:
                self.timer.stop()
            return
        if m.guided is not None:
            m.guided.advance(self.timer.interval() / 1000.0)
            self._show_pose()
            if m.guided.at_end:
                self.timer.stop()

    def _show_pose(self) -> None:
        cam = self.model.camera()
        if cam is not None:
            self.state.set_camera(cam)
            self.profile_view.set_eye(self.model.pose.position)

    def key(self, name: str) -> bool:
        """A flight key (:data:`FLY_KEYS`); True when it was used."""
        m = self.model
        if m is None or not m.flying or name not in FLY_KEYS:
            return False
        act = FLY_KEYS[name]
        if act[0] == "turn":
            m.turn(act[1], act[2])
        else:
            self.timer.stop() if m.guided is not None else None
            blocked = m.move(*(self.step_mm * a for a in act))
            if blocked:
                self.window.view3d.show_blocked()
        self._show_pose()
        return True

    def turn(self, yaw: float, pitch: float) -> None:
        if self.model is not None and self.model.flying:
            self.model.turn(yaw, pitch)
            self._show_pose()

    # -- video ----------------------------------------------------------------
    def _record(self) -> None:
        path, _ = QFileDialog.getSaveFileName(self, "Record the flythrough", "flythrough.mp4", "Video (*.mp4 *.gif)")
        if path:
            self.record(path)

    def record(self, path, size=(256, 256), fps: float = 10.0):
        """Render the automatic path to a video in the background; returns the task."""
        from dataclasses import replace

        from ..endoscopy import VideoWriter
        from ._view_picture import FrameJob, render_frame

        m = self.model
        poses = m.path().play(fps=fps)
        scene = replace(self.state.scene, volume=m.drawn_volume(), transfer=m.transfer(), mode="composite")

        def job(report):
            with VideoWriter(path, fps=fps) as w:
                for n, pose in enumerate(poses):
                    cam = pose.camera(fov=m.fov, near=0.5 * m.margin)
                    w.append(render_frame(FrameJob(scene=scene, camera=cam, size=size)).rgb)
                    report((n + 1) / len(poses))
            return path

        return run_task(self.window, job, lambda p: self.status.setText(f"Wrote {p}"),
                        lambda e: self.window.report_error("Recording failed", str(e)),
                        label="Recording the flythrough...", with_progress=True)

    # -- lumen mask, CPR -------------------------------------------------------
    def _choose_mask(self) -> None:
        path, _ = QFileDialog.getOpenFileName(self, "Lumen segmentation (label file)", "",
                                              "Segmentations (*.nii *.nii.gz *.nrrd *.mha *.mhd)")
        if path:
            self.set_mask_file(path)

    def set_mask_file(self, path, label=None) -> None:
        """Take the lumen from a segmentation file (label ``label``, or every non-zero voxel) at the next compute."""
        if self.model is not None:
            self.model.mask_file, self.model.label = path, label
            self.model.centerline = None
            self.status.setText(f"Lumen from {path}" + (f", label {label}" if label is not None else "") + ".")
            self._publish()

    def _save_cpr(self) -> None:
        path, _ = QFileDialog.getSaveFileName(self, "Save the curved planar reformation", "cpr.png", "PNG (*.png)")
        if path:
            self.save_cpr(path)

    def save_cpr(self, path):
        """Write the CPR of the kind chosen in the panel to ``path`` (PNG) in the background; returns the task."""
        m, kind = self.model, self.cpr_kind.currentText()

        def job():
            from PIL import Image as PILImage

            PILImage.fromarray(m.cpr(kind)).save(path)
            return path

        return run_task(self.window, job, lambda p: self.status.setText(f"Wrote {p}"),
                        lambda e: self.window.report_error("CPR failed", str(e)), label="Computing the CPR...")
