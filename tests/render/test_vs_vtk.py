"""The same scene through VTK's fixed-point CPU ray caster: an independent renderer must agree."""

from __future__ import annotations

import numpy as np
import pytest

from volumen.bench._vtk_peer import VtkScene, vtk_available
from volumen.core import Camera, Sampling, Scene, Shading, TransferFunction, Volume
from volumen.render import render

pytestmark = pytest.mark.skipif(not vtk_available(), reason="vtk is not installed (pip install 'volumen[bench]')")


def _blob_volume(n=48):
    z, y, x = (np.mgrid[0:n, 0:n, 0:n].astype(np.float32) - (n - 1) / 2)
    r = np.sqrt(x * x + 1.3 * y * y + 0.8 * z * z)
    data = 1000.0 * np.tanh((16.0 - r) / 2.5) + 200.0 * np.sin(x / 5.0)
    return Volume(np.rint(data).astype(np.int16), spacing=(1.2, 1.0, 0.9), affine=np.diag([0.9, 1.0, 1.2, 1.0]))


@pytest.mark.parametrize("shading, tol", [("none", 0.01), ("headlight", 0.03)])
def test_composite_agrees_with_vtk_fixed_point_mapper(shading, tol, output_dir):
    """Mean |RGB difference| over the image (values in [0, 1]): below 0.01 unshaded, 0.03 shaded
    (VTK quantizes normals and gradient shading differently; the unshaded integral must agree closely)."""
    vol = _blob_volume()
    tf = TransferFunction(color=((-1000, 0.2, 0.1, 0.05), (0, 0.9, 0.5, 0.3), (1200, 1.0, 1.0, 0.9)),
                          opacity=((-1000, 0.0), (-200, 0.0), (400, 0.08), (1200, 0.3)))
    scene = Scene(volume=vol, transfer=tf, shading=Shading(mode=shading),
                  sampling=Sampling(samples_per_voxel=2.0, jitter=False))
    camera = Camera.orbit(vol, view="anterior", azimuth=20, elevation=10, zoom=2.2)
    ours = np.clip(render(scene, camera, (96, 80)).rgba[..., :3], 0, 1)
    theirs = VtkScene(scene, camera, (96, 80), threads=1).render()
    assert ours.shape == theirs.shape
    covered = theirs.max(axis=2) > 0.02
    assert covered.mean() > 0.3, "the VTK picture is (nearly) empty: camera or TF not translated"
    diff = np.abs(ours - theirs)
    from PIL import Image as PILImage

    PILImage.fromarray((np.concatenate([ours, theirs, diff * 4], axis=1) * 255).clip(0, 255).astype(np.uint8)).save(
        output_dir / f"vs_vtk_{shading}.png")
    # both pictures cover the same pixels (up to the silhouette's one-pixel rim)
    ours_covered = ours.max(axis=2) > 0.02
    assert np.mean(covered != ours_covered) < 0.02
    assert diff.mean() < tol, f"mean |diff| {diff.mean():.4f}"


def test_vtk_peer_refuses_axes_it_cannot_represent():
    """vtkImageData is built without a direction: a permuted or flipped volume must be refused, not mis-drawn."""
    vol = _blob_volume(16)
    perm = np.zeros((4, 4))
    perm[0, 1] = perm[1, 0] = perm[2, 2] = perm[3, 3] = 1.0  # i -> +y, j -> +x
    permuted = Volume(vol.data, spacing=(1.0, 1.0, 1.0), affine=perm)
    scene = Scene(volume=permuted, transfer=TransferFunction.preset("ct-bone"), shading=Shading(mode="none"))
    with pytest.raises(ValueError, match="RAS"):
        VtkScene(scene, Camera.orbit(permuted), (8, 8))
