"""The endoscopy panel on a contrast-filled vessel: the lumen found from the data, shown as the slices' overlay,
the same lumen read back from a segmentation file, and the CPR saved as a PNG."""

from __future__ import annotations

import numpy as np


def test_panel_finds_a_contrast_lumen_overlays_it_and_saves_a_cpr(torso_flight, qtbot, tmp_path):
    import nibabel as nib
    from PIL import Image

    from volumen.app._endo_model import LUMENS
    from volumen.endoscopy import LUMEN_KINDS

    assert LUMENS == LUMEN_KINDS
    torso, win, panel = torso_flight
    aorta = torso.meta["truth"]["aorta"]
    m = panel.model
    assert m.estimate.kind == "contrast" and "contrast" in panel.status.text()
    overlay = np.asarray(win.state.mask.data, bool)
    dice = 2 * np.sum(overlay & aorta.mask) / (overlay.sum() + aorta.mask.sum())
    print(f"overlay: {overlay.sum()} voxels, Dice {dice:.3f} against the phantom's aorta")
    assert np.array_equal(overlay, m.mask) and dice >= 0.8
    first = m.centerline.points.copy()
    # the same lumen from a label file gives the same centerline
    nib.save(nib.Nifti1Image(np.where(m.mask, 5, 0).astype(np.int16).transpose(2, 1, 0), torso.affine),
             str(tmp_path / "seg.nii.gz"))
    panel.set_mask_file(str(tmp_path / "seg.nii.gz"), 5)
    task = panel.compute()
    qtbot.waitUntil(lambda: task.finished, timeout=60000)
    assert np.allclose(m.centerline.points, first)
    task = panel.save_cpr(str(tmp_path / "cpr.png"))
    qtbot.waitUntil(lambda: task.finished, timeout=60000)
    img = np.asarray(Image.open(tmp_path / "cpr.png"))
    assert img.ndim == 3 and img.shape[0] > 100 and img[..., 0].std() > 10
