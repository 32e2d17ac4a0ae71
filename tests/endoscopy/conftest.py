"""Fixtures of the endoscopy tests: the torso phantom's colon, its computed lumen and centerline, an analytic torus,
and the phantoms of anatomy the lumen estimate was not tuned on."""

from __future__ import annotations

import numpy as np
import pytest

from tests.endoscopy.endo_helpers import TORUS_H, TORUS_R, TORUS_RC
from volumen.core import Volume


@pytest.fixture(scope="session")
def torso():
    from volumen.data import phantom

    return phantom("torso")


@pytest.fixture(scope="session")
def unseen():
    """A factory of the issue-23 phantoms (arch, airways, tagged_colon, washout and airways with its pocket), each
    built once per session."""
    from volumen.data import phantom

    made = {}

    def get(name: str, **params):
        key = (name, tuple(sorted(params.items())))
        if key not in made:
            made[key] = phantom(name, **params)
        return made[key]

    return get


@pytest.fixture(scope="session")
def colon_lumen(torso):
    from volumen.endoscopy import lumen_mask

    return lumen_mask(torso, torso.meta["truth"]["colon"].centerline[0])


@pytest.fixture(scope="session")
def colon_centerline(torso, colon_lumen):
    from volumen.endoscopy import compute_centerline

    return compute_centerline(torso, colon_lumen)


@pytest.fixture(scope="session")
def endo_dir(output_dir):
    d = output_dir / "endoscopy"
    d.mkdir(exist_ok=True)
    return d


@pytest.fixture(scope="session")
def torus() -> Volume:
    n = int((TORUS_RC + TORUS_R + 6) * 2 / TORUS_H) + 1
    nz = int((TORUS_R + 6) * 2 / TORUS_H) + 1
    z, y, x = np.meshgrid(np.arange(nz), np.arange(n), np.arange(n), indexing="ij")
    ox, oz = -(n - 1) / 2 * TORUS_H, -(nz - 1) / 2 * TORUS_H
    X, Y, Z = ox + x * TORUS_H, ox + y * TORUS_H, oz + z * TORUS_H
    d = np.hypot(np.hypot(X, Y) - TORUS_RC, Z)
    data = np.clip(100.0 * (d - TORUS_R), -1000, 1000).astype(np.float32)
    aff = np.diag([TORUS_H, TORUS_H, TORUS_H, 1.0])
    aff[:3, 3] = (ox, ox, oz)
    return Volume(data, spacing=(TORUS_H,) * 3, affine=aff, modality="CT", units="HU")
