"""The label tag (``_pieces.ScanOnly`` / ``WithLabels``): a frame without a label map compiles its light paths without
the label classification.

The light paths (shadow rays, the illumination-volume sweeps, the path tracer's tracking) read the medium through
``_medium.depth_at``. Until the tag, a run-time branch on ``nlab`` chose the label-aware classification there, so
every shadow ray's loop held a call that never ran in a frame without labels, and paid for it: the whole-abdomen
CT's scattering frame (``ct-bone``, 3 lights, 782 x 415, adaptive) took 2-7 % longer with the branch than without it
(docs/design.md), the same picture to the bit.
"""

from __future__ import annotations

import re

import numpy as np
import pytest
from numba import njit

from volumen.core import Camera, LabelLayer, Light, Scene, Shading, TransferFunction
from volumen.data import organ_phantom
from volumen.render.raycast._medium import Medium, frame_medium
from volumen.render.raycast._pack import pack_frame
from volumen.render.raycast._pieces import ScanOnly, WithLabels, label_tag
from volumen.render.raycast._shadow import shadow_transmittance


@pytest.fixture(scope="module")
def organs():
    vol, labels = organ_phantom(24, spacing=2.0)
    c = np.asarray(vol.center)
    pos = c + vol.diagonal * np.array([0.6, -0.7, 0.5])
    light = Light(position=tuple(pos), direction=tuple(c - pos), exponent=2.0, intensity=1.0)
    tf = TransferFunction.preset("ct-soft-tissue", value_range=vol.value_range())
    scene = Scene(volume=vol, transfer=tf, lights=(light,), shading=Shading(mode="shadows", shadow_method="direct"))
    return scene, scene.with_(labels=LabelLayer(labels))


def test_a_frame_carries_the_label_tag_of_its_label_map(organs):
    plain, labelled = organs
    for scene, tag in ((plain, ScanOnly), (labelled, WithLabels)):
        s = pack_frame(scene, Camera.orbit(scene.volume), (16, 16)).settings
        assert type(s.labels) is tag and (s.nlabels > 0) == (tag is WithLabels)
    assert label_tag(0) == ScanOnly() and label_tag(3) == WithLabels()


def _compiled_shadow_ray(scene) -> str:
    """The LLVM code of ``shadow_transmittance`` compiled afresh (no cache) for the medium of ``scene``'s frame,
    after a shadow ray from the volume's centre."""
    frame = pack_frame(scene, Camera.orbit(scene.volume), (16, 16))
    a, s = frame.arrays, frame.settings
    med = njit(lambda a, s: frame_medium(a, s))(a, s)
    assert isinstance(med, Medium) and type(med.labels) is type(s.labels)
    fresh = njit(fastmath=True)(shadow_transmittance.py_func)
    t = fresh(med, a.cells, False, (a.geo, a.planes, 0), tuple(scene.volume.center), (1.0, 0.0, 0.0), 5.0,
              (s.ds0, s.ds0, 1.0))
    assert 0.0 <= t <= 1.0
    return fresh.inspect_llvm(fresh.signatures[0])


def test_a_shadow_ray_without_labels_compiles_no_label_classification(organs):
    """The shadow ray of a label-free frame has no call to the classification in it; a labelled frame's has."""
    plain, labelled = organs
    calls = re.compile(r"call [^\n]*_medium11_classified")
    assert not calls.search(_compiled_shadow_ray(plain))
    assert calls.search(_compiled_shadow_ray(labelled))
