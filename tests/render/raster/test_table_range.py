"""The renderers' table range (``core.table_range``): an MRI written as floats whose few outlier voxels lie
thousands of times past its tissue (``phantom("mr_head", dtype="float32", gain=1e4)``) draws as the same MRI with
outliers 4 times its brightest tissue, on the CPU and OpenGL ray casters and the texture slicer.

Spread over the outliers (up to 7.2e6 against tissue up to about 640), the 4,096-entry table and the int16
samples gave the tissue one entry: before ``table_range`` all three drew a mean RGB of 0.0089 against 0.193 (an
all but black picture, the outliers' specks). Measured since: mean |RGBA diff| 0.00013-0.00014 from the uint16
volume's picture (the table's entries fall at other values); the tolerance is 0.002.
"""

from __future__ import annotations

import numpy as np
import pytest

from volumen.core import Camera, Scene, Shading
from volumen.data import phantom
from volumen.render import default_transfer, render

TOL = 0.002


def _picture(volume, technique, device):
    scene = Scene(volume=volume, transfer=default_transfer(volume, "composite"), shading=Shading(mode="none"))
    kw = {"device": device} if device else {}
    return render(scene, Camera.orbit(volume, view="left"), (96, 96), technique=technique, **kw).rgba


@pytest.fixture(scope="module")
def volumes():
    return phantom("mr_head", size=64), phantom("mr_head", size=64, dtype="float32", gain=1e4)


@pytest.mark.parametrize("technique,device", [("raycast", "cpu"), ("raycast", "gl"), ("slicing", None)])
def test_far_outliers_of_a_float_mri_leave_its_tissue_drawn(gl, volumes, technique, device):
    plain, far = volumes
    assert float(far.data.max()) > 5000 * float(np.percentile(plain.data[plain.data > 0], 99))
    a, b = _picture(plain, technique, device), _picture(far, technique, device)
    diff = float(np.abs(a - b).mean())
    print(f"{technique} {device}: mean RGB {a[..., :3].mean():.4f} / {b[..., :3].mean():.4f}, mean |diff| {diff:.5f}")
    assert b[..., :3].mean() > 0.15
    assert diff <= TOL
