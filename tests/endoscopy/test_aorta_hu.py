"""The benchmarks' aorta in Hounsfield units (``volumen.bench._datasets.hu_aorta``): the scan's uncalibrated units
converted so the CT presets classify it as they would a calibrated CT angiogram."""

from __future__ import annotations

import numpy as np

from tests.endoscopy.aorta_data import aorta_folder, reference_lines
from volumen.bench._datasets import AORTA_HU, hu_aorta


def test_the_aorta_in_hu_reads_soft_tissue_and_a_contrast_lumen_where_a_ct_angiogram_does():
    """At the scan's own size (no resampling): its most common tissue reads as soft tissue (the histogram's mode
    within 0-100 HU; with the old +1000 shift it read about -800), and the lumen at VMTK's centerline points as
    contrast-filled blood (median 300-500 HU, as in CT angiograms)."""
    folder = aorta_folder()
    vol = hu_aorta((157, 393, 34))
    assert vol.units == "HU" and vol.data.dtype == np.int16
    counts, edges = np.histogram(vol.data, bins=np.arange(-50, 600, 10))
    mode = edges[np.argmax(counts[5:]) + 5]  # above the clipped floor (fat and air read 0 in the scan)
    print(f"mode {mode:.0f} HU; AORTA_HU {AORTA_HU}")
    assert 0 <= mode <= 100
    pts = np.concatenate(reference_lines(folder))
    ijk = np.rint(vol.world_to_index(pts)).astype(int)  # (i, j, k) = (x, y, z)
    lumen = vol.data[ijk[:, 2], ijk[:, 1], ijk[:, 0]]
    print(f"lumen at {len(pts)} centerline points: median {np.median(lumen):.0f} HU, "
          f"5-95 % {np.percentile(lumen, 5):.0f}..{np.percentile(lumen, 95):.0f}")
    assert 300 <= np.median(lumen) <= 500
