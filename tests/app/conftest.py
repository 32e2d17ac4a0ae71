"""Fixtures of the application tests: the head phantom at 64 voxels and windows with a 160x160 3D view."""

from __future__ import annotations

import pytest

pytest.importorskip("PySide6.QtWidgets", reason="the application needs PySide6 (extra 'gui') and the system libraries "
                    "Qt Widgets loads (libGL, libEGL, libxkbcommon)")
pytest.importorskip("pytestqt", reason="the application tests need pytest-qt")

HEAD_REF = "phantom:head?size=64"
VIEW = 160  # 3D view side, px


@pytest.fixture(autouse=True)
def no_background_compile(monkeypatch):
    """The windows of these tests compile nothing in the background (``volumen.app._warmup``; its own test turns
    it back on): a child process per window would cost the suite seconds each."""
    monkeypatch.setenv("VOLUMEN_WARM", "0")


@pytest.fixture(scope="session")
def head64():
    from volumen.data import phantom

    return phantom("head", size=64)


@pytest.fixture
def make_window(qtbot, tmp_path, head64, monkeypatch):
    """A factory of shown main windows with the head phantom loaded and the first picture refined."""
    monkeypatch.setenv("VOLUMEN_CONFIG_DIR", str(tmp_path / "config"))

    def make(load: bool = True, size=(900, 600), fixed: bool = True):
        from volumen.app import MainWindow

        win = MainWindow()
        qtbot.addWidget(win)
        if fixed:
            win.view3d.setFixedSize(VIEW, VIEW)
        win.resize(*size)
        win.show()
        qtbot.waitExposed(win)
        if load:
            win.set_volume(head64, HEAD_REF)
            assert win.wait_for_final(120)
        return win

    yield make


@pytest.fixture
def torso_flight(make_window, qtbot):
    """A window with the torso phantom whose endoscopy panel has found the lumen and path from one end of the
    phantom's aorta to the other: ``(torso, window, panel)``."""
    from volumen.data import phantom

    torso = phantom("torso")
    win = make_window(load=False)
    win.set_volume(torso, "phantom:torso")
    panel = win.endo_panel
    aorta = torso.meta["truth"]["aorta"]
    panel.pick("endo-start", aorta.centerline[0])
    panel.pick("endo-end", aorta.centerline[-1])
    task = panel.compute()
    qtbot.waitUntil(lambda: task.finished, timeout=120000)
    return torso, win, panel


@pytest.fixture(scope="session")
def app_output(output_dir):
    d = output_dir / "app"
    d.mkdir(exist_ok=True)
    return d
