"""Where the application can draw, decided before Qt starts: a display, or offscreen for ``--screenshot``.

Without a display (no ``DISPLAY``, no ``WAYLAND_DISPLAY``) Qt's X11 plugin aborts the process (exit 134,
a message about ``xcb-cursor0``), and so it does when X11 is there but the system library Qt 6.5+ needs to
load that plugin, ``libxcb-cursor0``, is missing. Here a screenshot, which needs no display, is drawn with
Qt's ``offscreen`` platform, and an interactive window that cannot open says so in one line
(:class:`~volumen.errors.NoDisplayError`, exit 1) with what to do. ``QT_QPA_PLATFORM`` set by the user is
left alone; so are other systems than Linux (Qt finds its own platform there).
"""

from __future__ import annotations

import ctypes.util
import os
import sys
from collections.abc import Callable, Mapping

from ..errors import NoDisplayError

__all__ = ["qt_platform", "prepare_platform"]

_NO_DISPLAY = ("no display to open a window on (DISPLAY and WAYLAND_DISPLAY are unset): run it in a desktop "
               "session or over 'ssh -X', save the window with --screenshot PNG (drawn offscreen), or use the "
               "browser viewer, 'volumen serve'")
_NO_XCB_CURSOR = ("Qt's X11 plugin needs the system library libxcb-cursor0, which is missing: install it "
                  "('sudo apt install libxcb-cursor0', or 'make system-libs' as root), or save the window with "
                  "--screenshot PNG (drawn offscreen)")


def qt_platform(*, screenshot: bool, environ: Mapping[str, str] | None = None,
                find_library: Callable[[str], str | None] = ctypes.util.find_library,
                system: str | None = None) -> str | None:
    """The Qt platform plugin the application must ask for, or None for Qt's own choice.

    Parameters
    ----------
    screenshot : bool
        Whether the window is only saved to a file (``volumen view --screenshot``): with no display it is drawn
        ``"offscreen"``.
    environ, find_library, system
        The environment, the system library lookup and ``sys.platform`` (default: this process's).

    Raises
    ------
    NoDisplayError
        An interactive window with no display, or an X11 display whose Qt plugin cannot load.
    """
    env = os.environ if environ is None else environ
    if env.get("QT_QPA_PLATFORM") or not (system or sys.platform).startswith("linux"):
        return None
    wayland, x11 = bool(env.get("WAYLAND_DISPLAY")), bool(env.get("DISPLAY"))
    if not (wayland or x11):
        if screenshot:
            return "offscreen"
        raise NoDisplayError(_NO_DISPLAY)
    if not wayland and find_library("xcb-cursor") is None:
        if screenshot:
            return "offscreen"
        raise NoDisplayError(_NO_XCB_CURSOR)
    return None


def prepare_platform(*, screenshot: bool) -> None:
    """Set ``QT_QPA_PLATFORM`` for :func:`qt_platform`'s answer, before the first ``QApplication`` (after it, Qt
    has its platform and nothing is checked)."""
    if "PySide6.QtWidgets" in sys.modules and sys.modules["PySide6.QtWidgets"].QApplication.instance() is not None:
        return
    name = qt_platform(screenshot=screenshot)
    if name is not None:
        os.environ["QT_QPA_PLATFORM"] = name
