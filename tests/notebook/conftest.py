"""Fixtures of the notebook tests: a small head phantom and its scene (the widget needs ipywidgets and jupyter-rfb)."""

from __future__ import annotations

import pytest

from volumen.core import Camera, Scene
from volumen.data import phantom
from volumen.render import default_transfer

pytest.importorskip("jupyter_rfb", reason="jupyter-rfb is not installed (pip install volumen[notebook])")

SIZE = (64, 64)


@pytest.fixture(scope="session")
def head32():
    return phantom("head", 32)


@pytest.fixture()
def scene(head32) -> Scene:
    return Scene(volume=head32, volume_ref="phantom:head", transfer=default_transfer(head32, "composite"))


@pytest.fixture(scope="session")
def view_size() -> tuple[int, int]:
    """(width, height) of the viewers under test."""
    return SIZE


@pytest.fixture()
def viewer(scene):
    from volumen.notebook._widget import Viewer

    w = Viewer(scene, Camera.orbit(scene.volume), SIZE)
    assert w.wait(300)
    yield w
    w.close()
