"""The series chooser: when a DICOM folder holds several image series, the user picks one.

One row per series (number, modality, size, files, description; the SeriesInstanceUID
in the tooltip), as :func:`volumen.io.list_series` gives them; double-click or OK
loads the chosen one. The dialog does not block (``open()``), so loading and
rendering go on behind it.
"""

from __future__ import annotations

from collections.abc import Callable

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QDialog, QDialogButtonBox, QLabel, QTableWidget, QTableWidgetItem, QVBoxLayout

__all__ = ["SeriesChooser", "ask_series"]

_COLUMNS = ("#", "Modality", "Size (x y slices)", "Files", "Description")


class SeriesChooser(QDialog):
    """A table of the series of ``path``; :meth:`chosen` is the selected SeriesInstanceUID."""

    def __init__(self, parent, path: str, series: list, notes: list[str] | None = None):
        super().__init__(parent)
        self.setWindowTitle("Choose a series")
        self.series = list(series)
        layout = QVBoxLayout(self)
        text = f"{path} holds {len(self.series)} image series; choose one to open."
        if notes:
            text += f"\n{len(notes)} file(s) were skipped (unreadable or not images)."
        self.label = QLabel(text)
        layout.addWidget(self.label)
        self.table = QTableWidget(len(self.series), len(_COLUMNS), self)
        self.table.setHorizontalHeaderLabels(_COLUMNS)
        self.table.setSelectionBehavior(QTableWidget.SelectRows)
        self.table.setSelectionMode(QTableWidget.SingleSelection)
        self.table.setEditTriggers(QTableWidget.NoEditTriggers)
        for row, s in enumerate(self.series):
            cells = (s.number or "-", s.modality, " x ".join(map(str, s.size)),
                     f"{s.files} (+{s.unreadable} unreadable)" if s.unreadable else str(s.files),
                     s.description or "(no description)")
            for col, value in enumerate(cells):
                item = QTableWidgetItem(value)
                item.setToolTip(s.uid)
                self.table.setItem(row, col, item)
        self.table.resizeColumnsToContents()
        self.table.selectRow(0)
        self.table.cellDoubleClicked.connect(lambda *_: self.accept())
        layout.addWidget(self.table)
        buttons = QDialogButtonBox(QDialogButtonBox.Ok | QDialogButtonBox.Cancel, Qt.Horizontal, self)
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        layout.addWidget(buttons)
        self.resize(640, 120 + 30 * min(len(self.series), 10))

    def choose(self, row: int) -> None:
        """Select row ``row`` (as a click would)."""
        self.table.selectRow(row)

    def chosen(self) -> str:
        """SeriesInstanceUID of the selected row."""
        rows = self.table.selectionModel().selectedRows()
        return self.series[rows[0].row() if rows else 0].uid


def ask_series(parent, path: str, series: list, on_chosen: Callable[[str], None],
               notes: list[str] | None = None) -> SeriesChooser:
    """Open a non-blocking :class:`SeriesChooser`; ``on_chosen(uid)`` runs when the user accepts."""
    dialog = SeriesChooser(parent, path, series, notes)
    dialog.setAttribute(Qt.WA_DeleteOnClose)
    dialog.accepted.connect(lambda: on_chosen(dialog.chosen()))
    dialog.open()
    return dialog
