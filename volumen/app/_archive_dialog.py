"""File > Open from archive...: search a PACS, look at each series' thumbnail, retrieve one, open it.

The dialog does not block (``open()``). Every request runs on a background :class:`~._tasks.Task`:
the search fills the results table (patient name and ID shown, because the user searched for them;
never written to the status line or a log), choosing a study lists its series with thumbnails, and
Retrieve fetches the chosen series into the cache with a progress bar and a Cancel button (what came is
kept for a later retrieve). When the series is in, ``retrieved(ref)`` carries its
``dicomweb://SERVER/STUDY/SERIES`` reference and the main window opens it like a file. Failures are one
line in the status label. A password neither in ``servers.toml`` nor in the environment is asked for here,
on the GUI thread before the first request, and remembered while the application runs.
"""

from __future__ import annotations

import threading

import numpy as np
from PySide6.QtCore import QSize, Qt, Signal
from PySide6.QtGui import QIcon, QImage, QPixmap
from PySide6.QtWidgets import (
    QComboBox,
    QDialog,
    QFormLayout,
    QHBoxLayout,
    QInputDialog,
    QLabel,
    QLineEdit,
    QListWidget,
    QListWidgetItem,
    QProgressBar,
    QPushButton,
    QTableWidget,
    QTableWidgetItem,
    QVBoxLayout,
)

from ._tasks import Task

__all__ = ["ArchiveDialog", "FIELDS", "THUMB"]

#: search field -> (label, keyword of volumen.pacs.find)
FIELDS = {"patient_name": "Patient name", "patient_id": "Patient ID", "date_from": "Date from (YYYYMMDD)",
          "date_to": "Date to (YYYYMMDD)", "modality": "Modality", "accession": "Accession",
          "description": "Description"}
_COLUMNS = ("Date", "Patient", "Patient ID", "Modality", "Accession", "Description", "Series")
THUMB = 64  # thumbnail side, px


def _pixmap(grey: np.ndarray | None) -> QPixmap:
    if grey is None:
        pix = QPixmap(THUMB, THUMB)
        pix.fill(Qt.darkGray)
        return pix
    grey = np.ascontiguousarray(grey, np.uint8)
    image = QImage(grey.data, grey.shape[1], grey.shape[0], grey.strides[0], QImage.Format_Grayscale8)
    return QPixmap.fromImage(image.copy()).scaled(THUMB, THUMB, Qt.KeepAspectRatio, Qt.SmoothTransformation)


class ArchiveDialog(QDialog):
    """Search, browse and retrieve; ``retrieved(ref)`` when a series is in the cache."""

    retrieved = Signal(str)

    def __init__(self, parent=None, servers: list[str] | None = None):
        super().__init__(parent)
        self.setWindowTitle("Open from archive")
        self._config_problem = ""
        self.studies: list = []
        self.series: list = []
        self.thumbnails: dict[str, np.ndarray | None] = {}
        self.task: Task | None = None
        self.cancel_event = threading.Event()
        layout = QVBoxLayout(self)
        layout.addLayout(self._server_row(servers))
        layout.addLayout(self._search_form())
        self.results = QTableWidget(0, len(_COLUMNS), self)
        self.results.setHorizontalHeaderLabels(_COLUMNS)
        self.results.setSelectionBehavior(QTableWidget.SelectRows)
        self.results.setSelectionMode(QTableWidget.SingleSelection)
        self.results.setEditTriggers(QTableWidget.NoEditTriggers)
        self.results.itemSelectionChanged.connect(self._study_selected)
        layout.addWidget(self.results, 2)
        self.series_list = QListWidget(self)
        self.series_list.setViewMode(QListWidget.IconMode)
        self.series_list.setIconSize(QSize(THUMB, THUMB))
        self.series_list.setResizeMode(QListWidget.Adjust)
        self.series_list.setGridSize(QSize(THUMB + 96, THUMB + 56))
        self.series_list.setWordWrap(True)
        self.series_list.setMinimumHeight(THUMB + 72)
        self.series_list.itemDoubleClicked.connect(lambda *_: self.retrieve())
        layout.addWidget(self.series_list, 1)
        bottom = QHBoxLayout()
        self.progress = QProgressBar(self)
        self.progress.setRange(0, 100)
        self.retrieve_button = QPushButton("Retrieve and open", self)
        self.retrieve_button.clicked.connect(self.retrieve)
        self.cancel_button = QPushButton("Cancel", self)
        self.cancel_button.setEnabled(False)
        self.cancel_button.clicked.connect(self.cancel)
        for w in (self.progress, self.retrieve_button, self.cancel_button):
            bottom.addWidget(w)
        layout.addLayout(bottom)
        self.status = QLabel(self._config_problem, self)
        self.status.setWordWrap(True)
        layout.addWidget(self.status)
        self.resize(820, 620)

    # -- layout ---------------------------------------------------------------
    def _server_row(self, servers: list[str] | None) -> QHBoxLayout:
        row = QHBoxLayout()
        self.server = QComboBox(self)
        self.server.setEditable(True)  # a name from servers.toml, a URL or AE_TITLE@HOST:PORT
        if servers is None:
            servers = self._configured()
        self.server.addItems(servers)
        self.protocol = QComboBox(self)
        self.protocol.addItems(["as configured", "dicomweb", "dimse"])
        self.search_button = QPushButton("Search", self)
        self.search_button.clicked.connect(self.search)
        for text, w in (("Server", self.server), ("Protocol", self.protocol)):
            row.addWidget(QLabel(text, self))
            row.addWidget(w, 1 if w is self.server else 0)
        row.addWidget(self.search_button)
        return row

    def _configured(self) -> list[str]:
        from ..errors import ArchiveError
        from ..pacs import load_servers

        try:
            return sorted(load_servers())
        except ArchiveError as exc:  # a bad servers.toml is reported in the status line, the dialog still opens
            self._config_problem = str(exc)
            return []

    def _search_form(self) -> QFormLayout:
        form = QFormLayout()
        self.fields = {}
        for key, label in FIELDS.items():
            edit = QLineEdit(self)
            edit.returnPressed.connect(self.search)
            form.addRow(label, edit)
            self.fields[key] = edit
        return form

    # -- helpers --------------------------------------------------------------
    def _where(self) -> dict:
        proto = self.protocol.currentText()
        return {"server": self.server.currentText().strip(), "protocol": None if proto == "as configured" else proto}

    def _query(self) -> dict:
        """The fields as keywords of ``volumen.pacs.find`` (dates joined into a range)."""
        v = {k: e.text().strip() for k, e in self.fields.items()}
        date_from, date_to = v.pop("date_from"), v.pop("date_to")
        if date_from or date_to:
            v["study_date"] = date_from if date_from == date_to else f"{date_from}-{date_to}"
        return {k: val for k, val in v.items() if val}

    def _ask(self, label: str, user: str) -> str | None:
        text, ok = QInputDialog.getText(self, "Archive password", f"password of {user} on {label}:",
                                        QLineEdit.Password)
        return text if ok and text else None

    def _unlocked(self) -> bool:
        """The server's password is at hand (asked for here, on the GUI thread, if it must be); else the reason is
        in the status line."""
        from ..errors import ArchiveError
        from ..pacs import resolve_server, unlock

        where = self._where()
        try:
            unlock(resolve_server(where["server"], protocol=where["protocol"]), self._ask)
        except ArchiveError as exc:
            self._failed(exc)
            return False
        return True

    def _start(self, fn, done, *, progress=None) -> Task | None:
        """Run ``fn`` in the background; errors go to the status line. One request at a time."""
        if not self._unlocked():
            return None
        self.task = Task(fn, self, with_progress=progress is not None)
        self.task.done.connect(done)
        self.task.error.connect(self._failed)
        if progress is not None:
            self.task.progress.connect(progress)
        self._busy(True)
        return self.task.start()

    def _busy(self, busy: bool) -> None:
        for w in (self.search_button, self.retrieve_button):
            w.setEnabled(not busy)

    def _failed(self, exc) -> None:
        self._busy(False)
        self.cancel_button.setEnabled(False)
        self.status.setText(str(exc).splitlines()[0] if str(exc) else type(exc).__name__)

    # -- search ---------------------------------------------------------------
    def search(self) -> Task | None:
        """Search studies with the fields; fills the results table."""
        from ..pacs import find

        where, query = self._where(), self._query()
        self.status.setText("searching...")
        return self._start(lambda: find(where["server"], protocol=where["protocol"], **query), self._found)

    def _found(self, studies) -> None:
        self._busy(False)
        self.studies = list(studies)
        self.results.setRowCount(len(self.studies))
        for row, s in enumerate(self.studies):
            cells = (s.date, s.patient_name, s.patient_id, "/".join(s.modalities), s.accession, s.description,
                     "" if s.n_series is None else str(s.n_series))
            for col, text in enumerate(cells):
                item = QTableWidgetItem(text)
                item.setToolTip(s.uid)
                self.results.setItem(row, col, item)
        self.results.resizeColumnsToContents()
        self.series_list.clear()
        self.status.setText(f"{len(self.studies)} stud{'y' if len(self.studies) == 1 else 'ies'} found")

    # -- series and thumbnails ------------------------------------------------
    def choose_study(self, row: int) -> None:
        self.results.selectRow(row)

    def _study_selected(self) -> None:
        rows = self.results.selectionModel().selectedRows()
        if rows:
            self.list_series(self.studies[rows[0].row()].uid)

    def list_series(self, study_uid: str) -> Task | None:
        """The series of a study, each with its thumbnail (fetched in the same background job)."""
        from ..pacs import series, thumbnail

        where = self._where()

        def work():
            found = series(where["server"], study_uid, protocol=where["protocol"])
            pictures = {}
            for s in found:
                try:
                    pictures[s.uid] = thumbnail(where["server"], study_uid, s.uid, size=THUMB,
                                                protocol=where["protocol"])
                except Exception:  # noqa: BLE001 - a series without a picture is still listed
                    pictures[s.uid] = None
            return found, pictures

        self.status.setText("listing the series...")
        return self._start(work, self._listed)

    def _listed(self, result) -> None:
        self._busy(False)
        self.series, self.thumbnails = result
        self.series_list.clear()
        for s in self.series:
            n = "? images" if s.n_instances is None else f"{s.n_instances} image{'' if s.n_instances == 1 else 's'}"
            item = QListWidgetItem(QIcon(_pixmap(self.thumbnails.get(s.uid))),
                                   f"#{s.number or '-'} {s.modality}\n{s.description or '-'}\n{n}")
            item.setToolTip(s.uid)
            self.series_list.addItem(item)
        if self.series:
            self.series_list.setCurrentRow(0)
        self.status.setText(f"{len(self.series)} series")

    def choose_series(self, row: int) -> None:
        self.series_list.setCurrentRow(row)

    # -- retrieve -------------------------------------------------------------
    def retrieve(self) -> Task | None:
        """Fetch the chosen series into the cache (progress bar; Cancel stops it); then ``retrieved(ref)``."""
        from ..pacs import make_ref, resolve_server, retrieve

        row = self.series_list.currentRow()
        if row < 0 or row >= len(self.series):
            self.status.setText("choose a series first")
            return None
        chosen = self.series[row]
        where = self._where()
        self.cancel_event.clear()
        self.progress.setValue(0)
        self.cancel_button.setEnabled(True)

        def work(report):
            server = resolve_server(where["server"], protocol=where["protocol"])
            folder = retrieve(server, chosen.study_uid, chosen.uid, cancel=self.cancel_event,
                              progress=lambda done, total: report(done / max(total, 1)))
            if server.name != where["server"] or "://" in server.name or "@" in server.name:
                return str(folder)  # a server given by address: its reference would not parse, open the folder
            return make_ref(server.name, chosen.study_uid, chosen.uid, server.kind)

        self.status.setText("retrieving...")
        return self._start(work, self._retrieved, progress=lambda f: self.progress.setValue(int(round(100 * f))))

    def cancel(self) -> None:
        """Stop the retrieve after the instance in flight (what came is kept for the next retrieve)."""
        self.cancel_event.set()

    def _retrieved(self, ref: str) -> None:
        """``ref`` is ``dicomweb://SERVER/STUDY/SERIES`` for a configured server, else the cached folder."""
        self._busy(False)
        self.cancel_button.setEnabled(False)
        self.progress.setValue(100)
        self.status.setText("retrieved; opening")
        self.retrieved.emit(ref)
