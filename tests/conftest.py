"""Shared fixtures: tests generate their own data; outputs go to test-output/."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="session")
def output_dir() -> Path:
    """A folder kept after the run (test-output/) for pictures worth looking at."""
    d = ROOT / "test-output"
    d.mkdir(exist_ok=True)
    return d
