"""Helpers of the analysis tests."""

from __future__ import annotations

import numpy as np


def on_truth(truth_line, points) -> np.ndarray:
    """The arc lengths (mm) of the true centerline's points closest to ``points``."""
    return np.array([truth_line.project(p)[0] for p in points])
