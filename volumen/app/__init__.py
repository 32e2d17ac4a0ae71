"""volumen.app: the desktop application (PySide6), the only package that imports Qt (docs/design.md section 1).

``run(path, screenshot=..., session=..., size=...)`` opens it (``volumen view``);
:class:`MainWindow` is the window; :class:`AppState` its Qt-free model.
Importing this package does not import Qt: the names load on first use.
"""

__all__ = ["run", "create_window", "MainWindow", "AppState"]


def __getattr__(name):
    if name in ("run", "create_window"):
        from . import _app

        return getattr(_app, name)
    if name == "MainWindow":
        from ._main_window import MainWindow

        return MainWindow
    if name == "AppState":
        from ._state import AppState

        return AppState
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
