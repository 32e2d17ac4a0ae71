"""Long jobs off the interface thread (loading files, meshes, centerlines, videos) and error dialogs.

:func:`run_task` runs a function in a Python thread and hands its result or
its exception back on the interface thread, optionally behind a progress
dialog. :func:`show_error` shows a message box that does not block (it is
opened, not executed), so a failure is reported and the application goes on.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

from PySide6.QtCore import QObject, Qt, Signal
from PySide6.QtWidgets import QMessageBox, QProgressDialog, QWidget

__all__ = ["run_task", "show_error", "Task"]


class Task(QObject):
    """One background job; ``done(result)`` or ``error(exception)`` arrive on the interface thread."""

    done = Signal(object)
    error = Signal(object)
    progress = Signal(float)

    def __init__(self, fn: Callable[..., Any], parent=None, *, with_progress: bool = False):
        super().__init__(parent)
        self._fn = fn
        self._with_progress = with_progress
        self.finished = False
        self.result = None
        self.exception = None
        self._thread = threading.Thread(target=self._run, daemon=True, name="volumen-task")

    def _run(self) -> None:
        try:
            res = self._fn(self.progress.emit) if self._with_progress else self._fn()
        except Exception as exc:  # noqa: BLE001 - every failure goes to the error handler
            self.exception = exc
            self.error.emit(exc)
        else:
            self.result = res
            self.done.emit(res)

    def start(self) -> Task:
        self._thread.start()
        return self

    def wait(self, timeout: float | None = None) -> bool:
        """Wait for the thread (tests, shutdown); True when it finished."""
        self._thread.join(timeout)
        return not self._thread.is_alive()


def run_task(parent: QWidget, fn: Callable[..., Any], on_done: Callable[[Any], None],
             on_error: Callable[[Exception], None], *, label: str | None = None,
             with_progress: bool = False) -> Task:
    """Run ``fn()`` (or ``fn(report)`` with ``with_progress``: ``report(fraction)``) in a thread.

    With ``label`` a progress dialog shows (busy bar, or the reported fraction)
    until the job ends. ``on_done(result)`` / ``on_error(exc)`` run on the interface thread.
    """
    task = Task(fn, parent, with_progress=with_progress)
    dialog = None
    if label is not None:
        dialog = QProgressDialog(label, None, 0, 100 if with_progress else 0, parent)
        dialog.setWindowModality(Qt.WindowModal)
        dialog.setMinimumDuration(300)
        dialog.setValue(0)
        task.progress.connect(lambda f: dialog.setValue(int(round(100 * f))))

    def finish():
        task.finished = True
        if dialog is not None:
            dialog.reset()
            dialog.deleteLater()
        tasks = getattr(parent, "_volumen_tasks", [])
        if task in tasks:
            tasks.remove(task)

    def ok(res):
        finish()
        on_done(res)

    def bad(exc):
        finish()
        on_error(exc)

    task.done.connect(ok)
    task.error.connect(bad)
    if not hasattr(parent, "_volumen_tasks"):
        parent._volumen_tasks = []
    parent._volumen_tasks.append(task)  # keep it alive until it ends
    return task.start()


def show_error(parent: QWidget, title: str, message: str) -> QMessageBox:
    """A non-blocking error box (``open()``, not ``exec()``); returns it."""
    box = QMessageBox(QMessageBox.Critical, title, message, QMessageBox.Ok, parent)
    box.setAttribute(Qt.WA_DeleteOnClose)
    box.open()
    return box
