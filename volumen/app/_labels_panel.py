"""The structures panel: a segmentation's structures with visibility, colour and opacity, drawn in 3-D.

"Open labels..." reads anything :func:`volumen.load_labels` reads onto the current scan's grid; the list
shows each structure with its volume in ml (:func:`volumen.measure.label_volumes`: its voxels times a voxel's
volume; tick: drawn; double-click: its colour); the opacity, the style (solid or the scan's
texture) and the unlabelled scan (kept or hidden) go into the scene's :class:`~volumen.core.LabelLayer`.
The drawn structures also show as the slice views' overlay.
"""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import Qt
from PySide6.QtGui import QColor
from PySide6.QtWidgets import (
    QCheckBox,
    QColorDialog,
    QComboBox,
    QFileDialog,
    QFormLayout,
    QListWidget,
    QListWidgetItem,
    QPushButton,
    QSlider,
    QVBoxLayout,
    QWidget,
)

__all__ = ["LabelsPanel"]


class LabelsPanel(QWidget):
    """Structures of a label map in the scene; ``window`` reports errors."""

    def __init__(self, state, window, parent=None):
        super().__init__(parent)
        self.state, self.window, self.labels = state, window, None
        self.colors: dict[str, tuple[float, float, float]] = {}
        open_button = QPushButton("Open labels...")
        open_button.clicked.connect(self.open_dialog)
        self.list = QListWidget()
        self.list.itemChanged.connect(lambda _item: self.apply())
        self.list.itemDoubleClicked.connect(self.pick_color)
        self.opacity = QSlider(Qt.Horizontal, minimum=0, maximum=100, value=80)
        self.opacity.valueChanged.connect(lambda _v: self.apply())
        self.style = QComboBox()
        self.style.addItems(["solid", "textured"])
        self.style.currentIndexChanged.connect(lambda _i: self.apply())
        self.scan = QCheckBox("Show the unlabelled scan")
        self.scan.setChecked(True)
        self.scan.toggled.connect(lambda _on: self.apply())
        form = QFormLayout()
        form.addRow("Opacity", self.opacity)
        form.addRow("Style", self.style)
        lay = QVBoxLayout(self)
        lay.addWidget(open_button)
        lay.addWidget(self.list)
        lay.addLayout(form)
        lay.addWidget(self.scan)

    def open_dialog(self) -> None:
        path = QFileDialog.getExistingDirectory(self, "Folder of masks (Cancel: pick a file)") or \
            QFileDialog.getOpenFileName(self, "Label map, .seg.nrrd or DICOM SEG")[0]
        if path:
            self.open(path)

    def open(self, path) -> None:
        """Read ``path`` onto the current scan's grid and list its structures (errors go to the window)."""
        from volumen.errors import VolumenError
        from volumen.io import load_labels

        if self.state.volume is None:
            return
        try:
            self.set_labels(load_labels(path, like=self.state.volume))
        except (VolumenError, OSError, ValueError) as exc:
            self.window.report_error("Labels", str(exc))

    def set_labels(self, labels) -> None:
        """Show ``labels`` (a LabelMap on the scan's grid): every structure listed and drawn."""
        self.labels = labels
        self.colors = {labels.names[v]: labels.colors[v] for v in labels.values}
        from volumen.measure import label_volumes

        ml = {m.value: m.ml for m in label_volumes(labels, scan=self.state.volume)}
        self.list.blockSignals(True)
        self.list.clear()
        for v in labels.values:
            item = QListWidgetItem(f"{labels.names[v]}  {ml.get(v, 0.0):.2f} ml")
            item.setData(Qt.UserRole, labels.names[v])
            item.setFlags(item.flags() | Qt.ItemIsUserCheckable)
            item.setCheckState(Qt.Checked)
            self._paint(item)
            self.list.addItem(item)
        self.list.blockSignals(False)
        self.apply()

    @staticmethod
    def name(item) -> str:
        """The structure a list item shows (its text adds the volume)."""
        return item.data(Qt.UserRole)

    def _paint(self, item) -> None:
        rgb = np.clip(np.asarray(self.colors[self.name(item)]) ** (1 / 2.2), 0, 1)
        item.setBackground(QColor(*(int(round(c * 255)) for c in rgb)))

    def pick_color(self, item) -> None:
        c = QColorDialog.getColor(parent=self)
        if c.isValid():
            self.colors[self.name(item)] = tuple((np.array(c.getRgbF()[:3]) ** 2.2).tolist())
            self._paint(item)
            self.apply()

    def shown(self) -> tuple[str, ...]:
        return tuple(self.name(self.list.item(i)) for i in range(self.list.count())
                     if self.list.item(i).checkState() == Qt.Checked)

    def apply(self) -> None:
        """Put the panel's choices into the scene and the shown structures into the slice overlay."""
        from volumen.core import LabelLayer

        if self.labels is None:
            return
        shown = self.shown()
        layer = LabelLayer(self.labels, show=shown, opacity=self.opacity.value() / 100.0, colors=dict(self.colors),
                           textured=self.style.currentText() == "textured",
                           scan="preset" if self.scan.isChecked() else "hidden")
        self.state.update_scene(labels=layer)
        values = [self.labels.value_of(n) for n in shown]
        self.state.set_mask(self.state.volume.with_data(np.isin(self.labels.data, values).view(np.uint8)))
