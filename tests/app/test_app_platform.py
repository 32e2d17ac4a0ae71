"""No display: ``volumen view`` says so in one line (exit 1) instead of Qt's abort; ``--screenshot`` draws offscreen."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from volumen.app._platform import qt_platform
from volumen.errors import NoDisplayError

_HAS = {"xcb-cursor": "libxcb-cursor.so.0"}.get


def _none(name):
    return None


def test_a_screenshot_without_a_display_is_drawn_offscreen():
    assert qt_platform(screenshot=True, environ={}, system="linux") == "offscreen"
    assert qt_platform(screenshot=True, environ={"DISPLAY": ":0"}, find_library=_none, system="linux") == "offscreen"


def test_a_window_without_a_display_is_a_one_line_error_saying_what_to_do():
    with pytest.raises(NoDisplayError, match="no display") as err:
        qt_platform(screenshot=False, environ={"HOME": "/tmp"}, find_library=_HAS, system="linux")
    assert "\n" not in str(err.value) and "--screenshot" in str(err.value)


def test_x11_without_qts_system_library_names_the_package():
    with pytest.raises(NoDisplayError, match="libxcb-cursor0") as err:
        qt_platform(screenshot=False, environ={"DISPLAY": ":0"}, find_library=_none, system="linux")
    assert "apt install libxcb-cursor0" in str(err.value)


@pytest.mark.parametrize("environ", [{"DISPLAY": ":0"}, {"WAYLAND_DISPLAY": "wayland-0"},
                                     {"QT_QPA_PLATFORM": "xcb"}])
def test_a_display_or_the_users_own_platform_is_left_to_qt(environ):
    find = _none if "DISPLAY" not in environ else _HAS
    assert qt_platform(screenshot=False, environ=environ, find_library=find, system="linux") is None
    assert qt_platform(screenshot=True, environ=environ, find_library=find, system="linux") is None
    assert qt_platform(screenshot=False, environ={}, system="darwin") is None


def test_volumen_view_without_a_display_exits_1_with_one_line():
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY", "QT_QPA_PLATFORM")}
    out = subprocess.run([sys.executable, "-m", "volumen", "view"], env=env, capture_output=True, text=True,
                         timeout=120, stdin=subprocess.DEVNULL)
    assert out.returncode == 1, out.stderr
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("volumen view: error: no display"), out.stderr
