"""Fixtures of the analysis tests: the stenosis phantom and its profile, grown from its landmarks and from its
true lumen mask, each made once per session."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="session")
def stenosis():
    from volumen.data import phantom

    return phantom("stenosis")


@pytest.fixture(scope="session")
def truth_line(stenosis):
    """The phantom's true centerline as a :class:`~volumen.endoscopy.Centerline` (radius: the analytic section's)."""
    from volumen.endoscopy import Centerline

    tube = stenosis.meta["truth"]["vessel"]
    return Centerline(tube.centerline, tube.radius, tube.arc_length)


@pytest.fixture(scope="session")
def profiles(stenosis):
    """``{"grown": Profile, "mask": Profile}``: from the start and end landmarks alone, and with the true lumen."""
    from volumen.analysis import profile

    lm = stenosis.meta["truth"]["landmarks"]
    mask = stenosis.meta["truth"]["vessel"].mask
    return {"grown": profile(stenosis, lm["start"], lm["end"]),
            "mask": profile(stenosis, lm["start"], lm["end"], lumen=mask)}
