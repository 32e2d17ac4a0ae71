"""Asking for the CUDA device without numba-cuda is one typed error naming the extra, never an import error from
inside the kernels (numba's built-in CUDA target lacks what they import)."""

from __future__ import annotations

import importlib.util

import numpy as np
import pytest

from volumen.core import Camera, Scene, Volume
from volumen.render import render
from volumen.render.cuda import CudaUnavailableError


def test_the_cuda_device_without_numba_cuda_names_the_extra(monkeypatch):
    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "numba_cuda" else real(name, *a))
    v = Volume(np.zeros((4, 4, 4), np.int16))
    with pytest.raises(CudaUnavailableError, match=r"numba-cuda is not installed \(pip install 'volumen\[cuda\]'\)"):
        render(Scene(volume=v), Camera.orbit(v), (8, 8), device="cuda")
