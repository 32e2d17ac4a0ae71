"""The renderers' table range (``core.table_range``): an MRI written as floats whose few outlier voxels lie
thousands of times past its tissue (``phantom("mr_head", dtype="float32", gain=1e4)``) draws as the same MRI with
outliers 4 times its brightest tissue, on the CPU and OpenGL ray casters and the texture slicer.

Spread over the outliers (up to 7.2e6 against tissue up to about 640), the 4,096-entry table and the int16
samples gave the tissue one entry: before ``table_range`` all three drew a mean RGB of 0.0089 against 0.193 (an
all but black picture, the outliers' specks). Measured since: mean |RGBA diff| 0.00013-0.00014 from the uint16
volume's picture (the table's entries fall at other values); the tolerance is 0.002.

The other end: a resampler's fill far below the scan outside its field of view (``data.fill_outside_field``),
which ``display_range`` and ``table_range`` cut off (the last test; its numbers are in its docstring).
"""

from __future__ import annotations

import numpy as np
import pytest

from volumen.core import Camera, Scene, Shading
from volumen.data import fill_outside_field, phantom
from volumen.render import default_transfer, render

TOL = 0.002
#: a fill far below: the fill-0 copy's picture within this (measured 0.00007-0.00008 for the MRI, 0.0027-0.0034 for
#: the CT, whose table then starts at -32768 HU: 8.8 HU an entry against 0.6); before the fix 0.073-0.095
FILL_TOL = 0.005


def _picture(volume, technique, device, shading="none"):
    scene = Scene(volume=volume, transfer=default_transfer(volume, "composite"), shading=Shading(mode=shading))
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


@pytest.mark.parametrize("technique,device", [("raycast", "cpu"), ("raycast", "gl"), ("slicing", None)])
def test_a_fill_far_below_draws_the_scan_not_a_milky_field_of_view(gl, technique, device):
    """A resampler's fill outside the field of view (``data.fill_outside_field``): an MRI filled with -1000 and
    -1e6 draws as the copy filled with 0, and a float CT filled with the lowest float as the copy filled with
    -1024 HU. Before ``display_range`` cut the fill off the MRI's range, its background sat high on
    ``mr-default``'s ramp and the field of view was drawn as an opaque, milky cylinder (mean RGB 0.25-0.28
    against 0.18); the CT's table spread over the fill drew a mean RGB of 0.19 against 0.096."""
    mr = phantom("mr_head", size=64, dtype="float32")
    ct = phantom("head", size=64)
    for src, base, fills, shading in ((mr, 0.0, (-1000.0, -1e6), "none"),
                                      (ct, -1024.0, (float(np.finfo(np.float32).min),), "headlight")):
        a = _picture(fill_outside_field(src, base), technique, device, shading)
        for fill in fills:
            b = _picture(fill_outside_field(src, fill), technique, device, shading)
            diff = float(np.abs(a - b).mean())
            print(f"{src.name} fill {fill:g}, {technique} {device}: mean RGB {a[..., :3].mean():.4f} / "
                  f"{b[..., :3].mean():.4f}, mean |diff| {diff:.5f}")
            assert diff <= FILL_TOL
