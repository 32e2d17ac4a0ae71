"""Phantoms built once per test session (noise-free and without the scanner blur: HU values are exact away
from the one-voxel partial-volume edges)."""

from __future__ import annotations

import pytest

from volumen.data import phantom


@pytest.fixture(scope="session")
def head():
    return phantom("head", noise=0, blur=0)


@pytest.fixture(scope="session")
def torso():
    return phantom("torso", noise=0, blur=0)

