"""Transfer functions: piecewise-linear evaluation, window/level, shift, presets, tables, JSON."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from volumen.core import PRESETS, TransferFunction


def test_piecewise_linear_evaluation():
    tf = TransferFunction(color=((0, 0, 0, 0), (100, 1, 0.5, 0), (200, 1, 1, 1)),
                          opacity=((0, 0), (50, 0), (150, 1)))
    out = tf.evaluate([-10, 0, 50, 75, 100, 150, 250])
    np.testing.assert_allclose(out[:, 0], [0, 0, 0.5, 0.75, 1, 1, 1], atol=1e-7)
    np.testing.assert_allclose(out[:, 1], [0, 0, 0.25, 0.375, 0.5, 0.75, 1], atol=1e-7)
    np.testing.assert_allclose(out[:, 3], [0, 0, 0, 0.25, 0.5, 1, 1], atol=1e-7)
    lut = tf.lut(0, 200, 5)
    assert lut.shape == (5, 4) and lut.dtype == np.float32
    np.testing.assert_allclose(lut[:, 3], [0, 0, 0.5, 1, 1], atol=1e-7)
    assert tf.visible_range() == (50.0, np.inf)


def test_window_level_and_shift():
    tf = TransferFunction.window_level(400, 40)
    np.testing.assert_allclose(tf.evaluate([-160, 40, 240])[:, 0], [0, 0.5, 1], atol=1e-7)
    np.testing.assert_allclose(tf.evaluate([-160, 40, 240])[:, 3], [0, 0.5, 1], atol=1e-7)
    bone = TransferFunction.preset("ct-bone")
    s = bone.shifted(100)
    assert s.opacity[0] == bone.opacity[0] and s.opacity[-1] == bone.opacity[-1]
    assert [p[0] for p in s.opacity[1:-1]] == [p[0] + 100 for p in bone.opacity[1:-1]]
    np.testing.assert_allclose(s.evaluate(741)[3], bone.evaluate(641)[3], atol=1e-6)
    big = bone.shifted(1e5)  # clamped inside the end points, still ordered
    assert all(a[0] <= b[0] for a, b in itertools.pairwise(big.opacity))


def test_presets():
    for name in PRESETS:
        tf = TransferFunction.preset(name, value_range=(0, 1000))
        assert tf.name == name and tf.evaluate(np.linspace(-3000, 3000, 50))[:, 3].max() > 0
    bone = TransferFunction.preset("ct-bone")
    assert bone.evaluate(-1000)[3] == 0 and bone.evaluate(1000)[3] > 0.5  # air clear, bone dense
    lung = TransferFunction.preset("ct-lung")
    assert lung.evaluate(-700)[3] > 0 and lung.evaluate(40)[3] == 0
    with pytest.raises(ValueError, match="ct-bone"):
        TransferFunction.preset("bone")
    with pytest.raises(ValueError, match="value_range"):
        TransferFunction.preset("mr-default")


def test_gradient_opacity_and_json():
    tf = TransferFunction(opacity=((0, 0), (10, 1)), gradient_opacity=((0, 0), (100, 1)), name="g")
    np.testing.assert_allclose(tf.gradient_factor([0, 50, 200]), [0, 0.5, 1])
    assert TransferFunction.from_json(tf.to_json()) == tf
    vessels = TransferFunction.preset("ct-vessels")
    assert TransferFunction.from_dict(vessels.to_dict()) == vessels


def test_validation():
    with pytest.raises(ValueError, match="non-decreasing"):
        TransferFunction(opacity=((10, 0), (0, 1)))
    with pytest.raises(ValueError, match=r"\[0, 1\]"):
        TransferFunction(opacity=((0, 0), (10, 2)))
    with pytest.raises(ValueError, match="unknown"):
        TransferFunction.from_dict({"opacity": [[0, 0]], "colour": []})
