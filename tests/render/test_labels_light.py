"""Label-aware light paths: shadow rays, illumination volumes and the path tracer see the structures drawn.

* a hidden structure casts no shadow: a cube over a plate, lit from above; with the cube hidden the picture
  equals the one of a label map without the cube (1e-5), with it shown its shadow darkens the plate (the
  plate's brightness, where the eye sees it, down by more than 15%; measured 25%); direct shadow rays,
  illumination volumes, and scattering;
* a label map whose every structure is drawn with the scan's own transfer function gives the unlabelled
  pictures: shadows and scattering (1e-4), path tracing (the same random paths: mean |difference| <= 1e-5).

Path tracing with labels converging like without: ``test_pathtrace`` runs its convergence tests on a label
scene too. About 3 s once the kernels are compiled: a frame with a uint8 label map has the types of one
without (the placeholder map is uint8 too), so labels add no kernel to compile.
"""

from __future__ import annotations

import numpy as np
import pytest

from volumen.core import Camera, LabelLayer, LabelMap, Light, Scene, Shading, TransferFunction, Volume
from volumen.data import organ_phantom
from volumen.render import PathTracer, render

SIZE = (48, 48)
N = 36


def _world(vol, ijk):
    return tuple(np.asarray(vol.affine, float) @ np.r_[np.asarray(ijk, float), 1.0])[:3]


@pytest.fixture(scope="module")
def cube_over_plate():
    """(volume, label map with cube 1 and plate 2, the same without the cube, camera, light from above)."""
    lab = np.zeros((N, N, N), np.uint8)
    lab[4:9, 4:32, 4:32] = 2  # [z, y, x]: a plate low in z
    lab[20:28, 12:24, 12:24] = 1  # a cube above it
    vol = Volume(np.zeros((N, N, N), np.int16), (1.0, 1.0, 1.0))
    names, colors = {1: "cube", 2: "plate"}, {1: (0.9, 0.3, 0.2), 2: (0.8, 0.8, 0.8)}
    both = LabelMap(lab, (1.0, 1.0, 1.0), vol.affine, names, colors)
    plate_only = LabelMap(np.where(lab == 1, 0, lab).astype(np.uint8), (1.0, 1.0, 1.0), vol.affine, names, colors)
    cam = Camera.orbit(vol, view="anterior", elevation=40.0, azimuth=25.0)
    light = Light(position=_world(vol, (18, 18, 90)), intensity=1.0)
    return vol, both, plate_only, cam, light


def _scene(vol, layer, light, shading):
    tf = TransferFunction.preset("ct-soft-tissue", value_range=(-1000, 1000))
    return Scene(volume=vol, transfer=tf, lights=(light,), shading=shading, labels=layer)


@pytest.mark.parametrize("shading", [Shading(mode="shadows", shadow_method="direct"), Shading(mode="shadows"),
                                     Shading(mode="scattering")], ids=["direct", "fast", "scattering"])
def test_a_hidden_structure_casts_no_shadow(cube_over_plate, shading):
    vol, both, plate_only, cam, light = cube_over_plate
    shown = render(_scene(vol, LabelLayer(both, scan="hidden"), light, shading), cam, SIZE)
    hidden = render(_scene(vol, LabelLayer(both, scan="hidden", show=("plate",)), light, shading), cam, SIZE)
    absent = render(_scene(vol, LabelLayer(plate_only, scan="hidden"), light, shading), cam, SIZE)
    np.testing.assert_allclose(hidden.rgba, absent.rgba, atol=1e-5)
    cube = render(_scene(vol, LabelLayer(both, scan="hidden", show=("cube",)), light, Shading(mode="none")), cam,
                  SIZE).rgba[..., 3] > 0.01
    plate = (absent.rgba[..., 3] > 0.5) & ~cube  # the plate where the cube does not hide it from the eye
    lum = shown.rgba[..., :3].sum(axis=-1)
    lum_absent = absent.rgba[..., :3].sum(axis=-1)
    assert np.all(lum[plate] <= lum_absent[plate] + 1e-5)
    print(f"plate brightness with the cube shown / absent: {lum[plate].sum() / lum_absent[plate].sum():.3f}")
    assert lum[plate].sum() < 0.85 * lum_absent[plate].sum()  # the cube's shadow on the plate


class _ScanRows(LabelLayer):
    """Every structure drawn with the scan's own transfer function: each row of the table the scan's row
    (``r < 0``: the transfer function's colour; textured, opacity 1)."""

    def table(self):
        t = super().table()
        t[:] = t[0]
        return t


@pytest.fixture(scope="module")
def organs():
    vol, labels = organ_phantom(40, spacing=2.0)
    cam = Camera.orbit(vol, azimuth=-30.0, elevation=15.0, zoom=1.2)
    c = np.asarray(vol.center)
    pos = c + vol.diagonal * np.array([0.6, -0.7, 0.5])
    light = Light(position=tuple(pos), direction=tuple(c - pos), exponent=2.0, intensity=1.0)
    tf = TransferFunction.preset("ct-soft-tissue", value_range=vol.value_range())
    plain = Scene(volume=vol, transfer=tf, lights=(light,))
    return plain, plain.with_(labels=_ScanRows(labels, scan="preset")), cam


@pytest.mark.parametrize("shading", [Shading(mode="shadows"), Shading(mode="shadows", shadow_method="direct"),
                                     Shading(mode="scattering", sigma_a=0.2, sigma_s=1.0)],
                         ids=["fast", "direct", "scattering"])
def test_labels_drawn_with_the_scan_transfer_function_light_like_the_scan(organs, shading):
    plain, labelled, cam = organs
    a = render(plain.with_(shading=shading), cam, SIZE)
    b = render(labelled.with_(shading=shading), cam, SIZE)
    assert a.rgba[..., 3].max() > 0.5
    np.testing.assert_allclose(b.rgba, a.rgba, atol=1e-4)


def test_path_tracing_labels_drawn_with_the_scan_transfer_function_trace_the_same_paths(organs):
    plain, labelled, cam = organs
    sh = Shading(mode="scattering", sigma_a=0.2, sigma_s=1.0, phase_g=0.3, pt_bounces=4, ambient=0.2)
    a = PathTracer(plain.with_(shading=sh), cam, (32, 32))
    b = PathTracer(labelled.with_(shading=sh), cam, (32, 32))
    # the same majorants: the same decisions
    np.testing.assert_array_equal(a.frame.arrays.majorant, b.frame.arrays.majorant)
    ia, ib = a.step(16), b.step(16)
    d = np.abs(ia.rgba - ib.rgba)
    print(f"path tracing, labels with the scan's rows vs none: mean |d| {d.mean():.2e}, max {d.max():.2e}, "
          f"pixels over 1e-5: {(d.max(axis=-1) > 1e-5).sum()}")
    assert ia.rgba[..., 3].max() > 0.5
    assert d.mean() <= 1e-5
