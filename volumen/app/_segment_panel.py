"""The segmentation panel: threshold or region growing from seeds clicked in the slice views, and meshes.

The mask (``volumen.segment``) shows as a red overlay in the slice views. A
mesh is extracted from it (``volumen.surface.extract_mesh``, in the
background with a progress bar), shown with or instead of the volume (this
needs OpenGL; otherwise the choice stays disabled with the reason), and
exported as STL, OBJ or PLY.
"""

from __future__ import annotations

from PySide6.QtWidgets import (
    QButtonGroup,
    QComboBox,
    QDoubleSpinBox,
    QFileDialog,
    QFormLayout,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QRadioButton,
    QVBoxLayout,
    QWidget,
)

from ._state import MESH_DISPLAYS
from ._tasks import run_task

__all__ = ["SegmentPanel"]


class SegmentPanel(QWidget):
    """Threshold / region growing and mesh extraction; ``window`` gives error reporting and the pick mode."""

    def __init__(self, state, window, parent=None):
        super().__init__(parent)
        self.state = state
        self.window = window
        self.method = QComboBox()
        self.method.addItems(["Region growing", "Threshold"])
        self.lo = QDoubleSpinBox(minimum=-1e5, maximum=1e5, value=200.0, decimals=0, singleStep=10)
        self.hi = QDoubleSpinBox(minimum=-1e5, maximum=1e5, value=3000.0, decimals=0, singleStep=10)
        self.pick = QPushButton("Pick seeds in the slices")
        self.pick.setCheckable(True)
        self.pick.toggled.connect(lambda on: window.set_pick_mode("seed" if on else None))
        clear = QPushButton("Clear seeds")
        clear.clicked.connect(state.clear_seeds)
        self.seeds_label = QLabel()
        run = QPushButton("Segment")
        run.clicked.connect(self.segment)
        remove = QPushButton("Clear mask")
        remove.clicked.connect(lambda: state.set_mask(None))
        form = QFormLayout()
        form.addRow("Method", self.method)
        form.addRow("Lower", self.lo)
        form.addRow("Upper", self.hi)
        seg = QGroupBox("Mask")
        sl = QVBoxLayout(seg)
        sl.addLayout(form)
        r1 = QHBoxLayout()
        r1.addWidget(self.pick)
        r1.addWidget(clear)
        sl.addLayout(r1)
        sl.addWidget(self.seeds_label)
        r2 = QHBoxLayout()
        r2.addWidget(run)
        r2.addWidget(remove)
        sl.addLayout(r2)

        self.extract = QPushButton("Extract mesh from mask")
        self.extract.clicked.connect(self.extract_mesh)
        self.export = QPushButton("Export mesh...")
        self.export.clicked.connect(self._export)
        self.show_group = QButtonGroup(self)
        mesh = QGroupBox("Mesh")
        ml = QVBoxLayout(mesh)
        ml.addWidget(self.extract)
        self.radios = {}
        labels = ("Hidden", "With the volume", "Instead of the volume")
        for n, (key, label) in enumerate(zip(MESH_DISPLAYS, labels, strict=True)):
            rb = QRadioButton(label)
            self.show_group.addButton(rb, n)
            ml.addWidget(rb)
            self.radios[key] = rb
        self.show_group.idClicked.connect(lambda n: state.set_display(mesh_display=MESH_DISPLAYS[n]))
        ml.addWidget(self.export)
        self.mesh_label = QLabel()
        ml.addWidget(self.mesh_label)
        lay = QVBoxLayout(self)
        lay.addWidget(seg)
        lay.addWidget(mesh)
        lay.addStretch(1)
        self.raster_ok, self.raster_reason = False, "checking whether OpenGL works..."
        for topic in ("seeds", "mask", "mesh", "display", "volume"):
            state.subscribe(topic, self.refresh)
        self.refresh()

    def set_raster_available(self, ok: bool, reason: str) -> None:
        self.raster_ok, self.raster_reason = ok, reason
        self.refresh()

    def refresh(self) -> None:
        st = self.state
        self.seeds_label.setText(f"{len(st.seeds)} seed(s)")
        self.extract.setEnabled(st.mask is not None)
        self.export.setEnabled(st.mesh is not None)
        for key, rb in self.radios.items():
            rb.setEnabled(st.mesh is not None and (key == "hidden" or self.raster_ok))
            rb.setToolTip("" if self.raster_ok or key == "hidden" else self.raster_reason)
            rb.setChecked(st.mesh_display == key)
        m = st.mesh
        self.mesh_label.setText("" if m is None else f"{len(m.faces)} triangles")

    def segment(self) -> None:
        """Run the chosen method on the volume; the mask goes into the state."""
        from ..segment import region_grow, threshold

        st = self.state
        if st.volume is None:
            return
        lo, hi = self.lo.value(), self.hi.value()
        try:
            if self.method.currentText() == "Threshold":
                mask = threshold(st.volume, lo, hi)
            else:
                if not st.seeds:
                    raise ValueError("click one or more seeds in the slice views first")
                mask = region_grow(st.volume, [list(s) for s in st.seeds], lo=lo, hi=hi)
        except ValueError as exc:
            self.window.report_error("Segmentation failed", str(exc))
            return
        st.set_mask(mask)

    def extract_mesh(self):
        """Extract a mesh of the mask's boundary in the background; returns the task."""
        from ..surface import extract_mesh

        st = self.state
        if st.mask is None:
            return None
        vol, mask = st.volume, st.mask

        def job(report):
            return extract_mesh(vol, mask=mask, smooth_iterations=10, progress=report)

        def done(mesh):
            st.set_mesh(mesh, "with-volume" if self.raster_ok else "hidden")

        return run_task(self.window, job, done, lambda e: self.window.report_error("Mesh extraction failed", str(e)),
                        label="Extracting the mesh...", with_progress=True)

    def _export(self) -> None:
        path, _ = QFileDialog.getSaveFileName(self, "Export mesh", "mesh.stl", "Meshes (*.stl *.obj *.ply)")
        if path:
            self.export_mesh(path)

    def export_mesh(self, path) -> None:
        """Write the mesh (STL, OBJ or PLY by suffix); errors go to a dialog."""
        from ..surface import write_mesh

        try:
            write_mesh(self.state.mesh, path)
        except Exception as exc:  # noqa: BLE001 - reported, never a crash
            self.window.report_error("Mesh export failed", str(exc))
