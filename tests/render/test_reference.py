"""The ray caster draws the pictures it drew before its rewrite: every mode x every shading.

``reference_pictures.npz`` holds the pictures of :mod:`reference_scenes` as
rendered by the renderer before its rewrite (uint16-quantized rgba).
Bar (the issue's): mean |RGBA diff| <= 0.002 per picture; the p99 of the
per-channel differences is printed (not asserted: path-traced pictures are
noisy by nature, and a handful of pixels may flip on a threshold).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tests.render import reference_scenes
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
def test_every_sample_type_draws_the_same_with_the_one_int16_kernel(name):
    """An int16 volume is sampled in place; float32, int32 and read-only int16 copies of it are made int16
    (quantized, shifted, shifted: ``_precompute.int16_samples``) and drawn by the same compiled kernel, no
    compile of their own, to the same pictures.

    Two modes: every mode and shading reads its samples through the one ``_sample.reconstruct``."""
    from volumen.core import Volume
    from volumen.render.raycast import prepare
    from volumen.render.raycast._march import _trace_tiles

    scene, cam, size = reference_scenes.scenes()[name]
    v = scene.volume
    meta = dict(spacing=v.spacing, affine=v.affine, modality=v.modality, units=v.units)
    ints = Volume(np.rint(v.data).astype(np.int16), **meta)
    frozen = ints.data.copy()
    frozen.flags.writeable = False
    others = {"float32": Volume(ints.data.astype(np.float32), **meta),
              "int32": Volume(ints.data.astype(np.int32), **meta),
              "read-only int16": Volume(frozen, **meta)}
    assert prepare(ints).u is ints.data
    a = render(scene.with_(volume=ints), cam, size).rgba
    kernels = len(_trace_tiles.signatures)
    for kind, vol in others.items():
        assert prepare(vol).u.dtype == np.int16 and prepare(vol).u is not vol.data
        b = render(scene.with_(volume=vol), cam, size).rgba
        d = np.abs(a.astype(np.float64) - b)
        print(f"{name}: int16 in place vs {kind}: mean |diff| {d.mean():.2e}, max {d.max():.2e}")
        assert d.mean() <= 1e-4, kind
    assert len(_trace_tiles.signatures) == kernels
