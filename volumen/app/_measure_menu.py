"""The Measure menu: choose the tool (none; ruler, rectangle, ellipse on the slice views; the 3-D view's ruler),
import measurements (a DICOM SR, a session or a measurements JSON: ``volumen.load_measurements``) and export them
as CSV, JSON or a DICOM SR, as ``volumen measure export`` writes them."""

from __future__ import annotations

from PySide6.QtGui import QActionGroup
from PySide6.QtWidgets import QFileDialog

from ._slice_measures import TOOLS

__all__ = ["build_measure_menu", "set_tool", "export", "import_measurements"]


#: the tools of the Measure menu: the slice views' and the 3-D view's ruler
MENU_TOOLS = (*TOOLS, "ruler3d")


def set_tool(window, tool: str | None) -> None:
    """Give ``window`` the measurement ``tool``: one of the slice views' (a left drag there places it), ``ruler3d``
    (two clicks on the 3-D picture), or None (a left drag moves the crosshair and orbits)."""
    for view in window.slices.values():
        view.measure_tool.set_tool(tool if tool in TOOLS else None)
    window.view3d.ruler3d.set_active(tool == "ruler3d")


def export(window, path) -> None:
    """Write the window's measurements to ``path``: a DICOM SR for ``.dcm``, else CSV or JSON by the suffix."""
    from ..measure import make_sr, save_measurements

    items = window.state.measurements
    if str(path).lower().endswith(".dcm"):
        make_sr(items, window.state.volume).save_as(path, enforce_file_format=True)
    else:
        save_measurements(items, path)


def import_measurements(window, path) -> int:
    """Add the measurements of ``path`` (an SR, a session or a measurements JSON) to ``window``'s; returns how many.

    Raises
    ------
    volumen.errors.MeasurementError
        Measurements of another scan, an SR of another study (nothing is added).
    """
    from ..measure import load_measurements

    found = load_measurements(path, volume=window.state.volume)
    window.state.set_measurements([*window.state.measurements, *found])
    return len(found)


def _import_dialog(window) -> None:
    path, _ = QFileDialog.getOpenFileName(window, "Import measurements", "", "DICOM SR or JSON (*.dcm *.json)")
    if not path:
        return
    try:
        n = import_measurements(window, path)
    except Exception as exc:  # noqa: BLE001 - reported, the measurements already there stay
        window.report_error("Cannot import the measurements", str(exc))
        return
    window.statusBar().showMessage(f"{n} measurement(s) imported", 5000)


def _export_dialog(window) -> None:
    path, _ = QFileDialog.getSaveFileName(window, "Export the measurements", "measurements.csv",
                                          "CSV (*.csv);;JSON (*.json);;DICOM SR (*.dcm)")
    if not path:
        return
    try:
        export(window, path)
    except Exception as exc:  # noqa: BLE001 - reported, never a crash (a scan not read from DICOM, a full disk)
        window.report_error("Cannot export the measurements", str(exc))


def build_measure_menu(window) -> None:
    """Add the Measure menu to ``window``'s menu bar."""
    menu = window.menuBar().addMenu("&Measure")
    group = QActionGroup(menu)
    names = {None: "Crosshair (no tool)", "ruler3d": "Ruler in 3-D (two clicks on the picture)"}
    for tool in (None, *MENU_TOOLS):
        action = menu.addAction(names.get(tool, (tool or "").capitalize()))
        action.setCheckable(True)
        action.setChecked(tool is None)
        action.triggered.connect(lambda _=False, t=tool: set_tool(window, t))
        group.addAction(action)
    menu.addSeparator()
    menu.addAction("Import measurements...", lambda: _import_dialog(window))
    menu.addAction("Export measurements...", lambda: _export_dialog(window))
