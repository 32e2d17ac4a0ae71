"""The Structures panel: a TotalSegmentator-style folder opened onto the scan, visibility and opacity in the
scene's label layer, the shown structures as the slice overlay, and the drawn picture changing. About 20 s."""

from __future__ import annotations

import nibabel as nib
import numpy as np


def test_structures_panel(make_window, tmp_path):
    from volumen.data import organ_phantom

    vol, labels = organ_phantom(48)
    for v, n in labels.names.items():
        data = (labels.data == v).astype(np.uint8).transpose(2, 1, 0)
        nib.save(nib.Nifti1Image(data, labels.affine), str(tmp_path / f"{n}.nii.gz"))
    win = make_window(load=False)
    win.set_volume(vol, "phantom:organs?size=48")
    assert win.wait_for_final(120)
    panel = win.labels_panel
    panel.open(tmp_path)
    assert sorted(panel.shown()) == sorted(labels.names.values())
    layer = win.state.scene.labels
    assert layer.opacity == 0.8 and len(layer.show) == 5
    assert win.state.mask.data.sum() == (labels.data > 0).sum()
    liver = next(i for i in range(panel.list.count()) if panel.name(panel.list.item(i)) == "liver")
    from PySide6.QtCore import Qt

    panel.list.item(liver).setCheckState(Qt.Unchecked)
    layer = win.state.scene.labels
    assert "liver" not in [layer.labels.names[v] for v in layer.show]
    assert win.state.mask.data.sum() == ((labels.data > 0) & (labels.data != 1)).sum()
    panel.open(tmp_path / "missing")  # a bad path: one error, no crash
    assert win.last_error[0] == "Labels" and "missing" in win.last_error[1]


def test_each_structure_shows_its_volume_in_ml(make_window):
    """A sphere label of radius 20 mm on a 1 mm grid (the voxels whose centres lie inside): the volume the panel
    shows is within 1 % of 4/3 pi r^3."""
    from volumen.core import LabelMap
    from volumen.data import phantom

    vol = phantom("sphere", 64, radius=20.0)
    r = vol.meta["truth"]["radius"]
    inside = (np.asarray(vol.data) > 0).astype(np.uint8)
    labels = LabelMap(inside, spacing=vol.spacing, affine=vol.affine, names={1: "ball"})
    win = make_window(load=False)
    win.set_volume(vol, "phantom:sphere")
    assert win.wait_for_final(120)
    win.labels_panel.set_labels(labels)
    (text,) = [win.labels_panel.list.item(i).text() for i in range(win.labels_panel.list.count())]
    name, ml, unit = text.split()
    assert name == "ball" and unit == "ml"
    assert abs(float(ml) - 4 / 3 * np.pi * r**3 / 1000) < 0.01 * (4 / 3 * np.pi * r**3 / 1000)
