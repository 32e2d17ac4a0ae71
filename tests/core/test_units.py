"""Numbers a user reads are printed in their units' precision (``core.value_text``, ``core.mm_text``)."""

from __future__ import annotations

import numpy as np

from volumen.core import Volume, mm_text, range_text, value_text, values_of


def test_hounsfield_units_and_integer_data_read_whole():
    assert value_text(298.972, "HU") == "299" and value_text(-598.585, "HU+1000") == "-599"
    assert value_text(-0.2, "HU") == "0" and value_text(-0.0) == "0"
    assert range_text(335.981, 3343, "HU") == "336..3343"


def test_other_values_read_to_four_significant_digits():
    assert value_text(335.981) == "336" and value_text(0.123456) == "0.1235" and value_text(1e-5) == "1e-05"
    assert value_text(123456.7) == "123457" and value_text(float("nan")) == "nan"


def test_millimetres_read_to_a_tenth():
    assert mm_text(16.04) == "16.0" and mm_text(-0.04) == "0.0" and mm_text(39.66) == "39.7"


def test_a_volume_says_how_its_values_read():
    ct = Volume(np.zeros((2, 2, 2), np.int16), spacing=(1, 1, 1), units="HU")
    mr = Volume(np.zeros((2, 2, 2), np.int16), spacing=(1, 1, 1))
    assert value_text(298.972, **values_of(ct)) == "299" and value_text(310.5, **values_of(mr)) == "310.5"


def test_the_lumen_line_reads_whole_hounsfield_units():
    from volumen.endoscopy import LumenEstimate

    est = LumenEstimate(kind="contrast", value_range=(335.981, 3343.0), threshold=298.972, spread=10.0, lumen=462.0,
                        wall=135.944)
    line = est.describe("HU")
    assert "values 336..3343, wall threshold 299 (lumen 462, wall 136)" in line
