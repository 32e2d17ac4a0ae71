"""The ray caster draws the pictures it drew before its rewrite (issue 13): every mode x every shading.

``reference_pictures.npz`` holds the pictures of :mod:`reference_scenes` as
rendered by the renderer before issue 13's changes (uint16-quantized rgba).
Bar (the issue's): mean |RGBA diff| <= 0.002 per picture; the p99 of the
per-channel differences is printed (not asserted: path-traced pictures are
noisy by nature, and a handful of pixels may flip on a threshold).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import reference_scenes

from volumen.render import render

REF = Path(__file__).parent / "reference_pictures.npz"
MEAN_TOL = 0.002


@pytest.fixture(scope="module")
def reference():
    return dict(np.load(REF))


def _diff(name, reference):
    if name not in reference:
        pytest.skip(f"{name}: no reference picture (its volume was missing when the references were written)")
    scene, cam, size = reference_scenes.scenes()[name]
    new = reference_scenes.quantize(render(scene, cam, size).rgba).astype(np.float64) / 65535
    return np.abs(new - reference[name].astype(np.float64) / 65535)


@pytest.mark.parametrize("name", list(reference_scenes.scenes()))
def test_picture_matches_reference(name, reference):
    d = _diff(name, reference)
    print(f"{name}: mean |diff| {d.mean():.2e}, p99 {np.percentile(d, 99):.2e}, max {d.max():.2e}")
    assert d.mean() <= MEAN_TOL, (name, d.mean())


def test_every_reference_is_drawn():
    """The reference file and the scene list agree (a scene dropped from the list would go unchecked)."""
    names = set(reference_scenes.scenes())
    stored = set(np.load(REF).files)
    if reference_scenes.AORTA is None:
        stored = {n for n in stored if not n.startswith("aorta/")}
        print(f"the VMTK aorta is missing: its {len(np.load(REF).files) - len(stored)} pictures not checked")
    assert names == stored


@pytest.mark.parametrize("name", ["torso/mip", "torso/composite/headlight"])
def test_integer_data_sampled_directly_draws_the_same(name):
    """An int16 volume is sampled in place (no normalized float copy): the same pictures as its float32 copy.

    Two modes: every mode and shading reads its samples through the one ``_sample.reconstruct``, and each
    float32 variant costs 15-90 s of cold compilation (the float32 isosurface, MinIP and pre-integrated
    kernels are checked by test_isosurface, test_projections and test_sampling)."""
    from volumen.core import Volume
    from volumen.render.raycast import prepare

    scene, cam, size = reference_scenes.scenes()[name]
    v = scene.volume
    meta = dict(spacing=v.spacing, affine=v.affine, modality=v.modality, units=v.units)
    ints = Volume(np.rint(v.data).astype(np.int16), **meta)
    floats = Volume(ints.data.astype(np.float32), **meta)
    assert prepare(ints).u is ints.data and prepare(floats).u is not floats.data
    unsigned = Volume((ints.data - ints.data.min()).astype(np.uint16), **meta)  # would wrap in place: copied
    assert prepare(unsigned).u.dtype == np.float32
    a = render(scene.with_(volume=ints), cam, size).rgba
    b = render(scene.with_(volume=floats), cam, size).rgba
    d = np.abs(a.astype(np.float64) - b)
    print(f"{name}: int16 in place vs float32 copy: mean |diff| {d.mean():.2e}, max {d.max():.2e}")
    assert d.mean() <= 1e-4
