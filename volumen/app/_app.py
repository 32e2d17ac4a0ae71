"""Starting the application: ``run(path, screenshot=..., session=..., size=...)``.

With ``screenshot`` the window opens, waits for the refined 3D picture, saves
the whole window as PNG and exits: scripted pictures for the documentation
and the tests.
"""

from __future__ import annotations

import sys

__all__ = ["run", "create_window", "DEFAULT_DATA"]

#: what opens when no path is given
DEFAULT_DATA = "phantom:head"


def _application():
    from PySide6.QtWidgets import QApplication

    app = QApplication.instance()
    return app if app is not None else QApplication(sys.argv[:1])


def create_window(path: str | None = None, *, session: str | None = None, size: tuple[int, int] | None = None,
                  wait: bool = False):
    """A shown :class:`MainWindow` with ``path`` (default the head phantom) or a session loaded.

    ``wait`` loads synchronously (errors are raised, not shown); otherwise the
    data loads in the background and errors go to a dialog.
    """
    from ._main_window import MainWindow
    from ._session import resolve_volume

    _application()
    ref = path or DEFAULT_DATA
    volume = resolve_volume(ref) if (wait and session is None) else None  # fail before any window exists
    win = MainWindow()
    if size is not None:
        win.resize(*size)
    win.show()
    try:
        if session is not None:
            if not win.load_session(session) and wait:
                where, problem = win.last_error
                raise ValueError(f"{where}: {problem}")
        elif wait:
            win.set_volume(volume, ref)
        else:
            win.open_path(ref)
    except BaseException:
        win.close()  # stops the render thread before the interpreter shuts down
        raise
    return win


def run(path: str | None = None, *, screenshot: str | None = None, session: str | None = None,
        size: tuple[int, int] | None = None, timeout: float = 300.0) -> int:
    """Open the application; returns the exit code.

    Parameters
    ----------
    path : str or None
        A volume file, a DICOM folder or ``phantom:NAME``; None opens the head phantom.
    screenshot : str or None
        Save the whole window to this PNG once the refined picture is shown, then exit.
    session : str or None
        A session file to load (it names its data; ``path`` is then ignored).
    size : (width, height) or None
        Window size in pixels.
    timeout : float, s
        Longest wait for the picture in screenshot mode.
    """
    from ._platform import prepare_platform
    from ._screenshot import save_widget

    prepare_platform(screenshot=screenshot is not None)  # before Qt: a one-line error instead of Qt's abort
    app = _application()
    if screenshot is None:
        win = create_window(path, session=session, size=size)
        return int(app.exec())
    win = create_window(path, session=session, size=size, wait=True)
    ok = win.wait_for_final(timeout)
    if not ok:
        print("volumen view: the picture did not finish in time", file=sys.stderr)
    save_widget(win, screenshot)
    print(f"wrote {screenshot}")
    win.close()
    return 0 if ok else 1
