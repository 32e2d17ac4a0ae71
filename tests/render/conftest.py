"""Fixtures of the renderer tests (helpers live in render_helpers.py)."""

from __future__ import annotations

import pytest

from tests.render.render_helpers import sphere_volume
from volumen.core import Volume


@pytest.fixture(scope="session")
def ball() -> Volume:
    return sphere_volume()


@pytest.fixture(scope="session")
def render_dir(output_dir):
    d = output_dir / "render"
    d.mkdir(exist_ok=True)
    return d
