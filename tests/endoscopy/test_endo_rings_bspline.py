"""Smooth reconstruction: the tricubic B-spline takes away the concentric terraces that
trilinear reconstruction draws on the wall of a thick-slice scan."""

from __future__ import annotations

import numpy as np
from test_endo_rings_cpr import ring_energy

from volumen.data import phantom
from volumen.endoscopy import Endoscope, Pose


def test_bspline_takes_the_slices_terraces_off_a_thick_slice_wall(output_dir):
    """Inside a smooth-walled sphere (radius 14 mm, a 1.5 mm logistic edge: a scanner's blur) scanned in 3 mm
    slices with 1 mm pixels, looking across the slices from its centre: every slice draws a ring on the
    trilinear wall (its gradient jumps at each slice); the B-spline's ring energy is at least 4x lower (measured
    0.0035 -> 0.00035). Analytically every ray meets the wall head-on under the headlight, a uniform picture: the
    B-spline's luminance varies at least 2x less over the view."""
    vol = phantom("sphere", size=(12, 36, 36), spacing=(3.0, 1.0, 1.0), radius=14.0, inside=300.0, outside=40.0,
                  edge=1.5)
    pose = Pose(position=(0.0, 0.0, 0.0), forward=(0.0, 0.0, 1.0), up=(0.0, 1.0, 0.0))
    endo = Endoscope(volume=vol, threshold=170.0, shading="headlight", samples_per_voxel=4.0)
    tri = endo.render(pose, (64, 64))
    bsp = endo.with_(interpolation="bspline").render(pose, (64, 64))
    e_tri, e_bsp = ring_energy(tri), ring_energy(bsp)
    sd_tri, sd_bsp = (float(np.std(im.rgba[..., :3].mean(axis=2))) for im in (tri, bsp))
    print(f"ring energy: trilinear {e_tri:.5f}, B-spline {e_bsp:.5f} ({e_tri / e_bsp:.1f}x); luminance std "
          f"{sd_tri:.4f} vs {sd_bsp:.4f}")
    tri.save(output_dir / "rings_trilinear.png")
    bsp.save(output_dir / "rings_bspline.png")
    assert np.all(tri.rgba[..., 3] > 0.99) and np.all(bsp.rgba[..., 3] > 0.99)  # the wall fills the view
    assert e_bsp * 4 <= e_tri
    assert sd_bsp * 2 <= sd_tri
