"""The volume of each structure of a label map: its voxel count times one voxel's volume."""

from __future__ import annotations

import numpy as np

from ._model import LabelVolume, Measurements, Scan

__all__ = ["label_volumes"]


def label_volumes(labels, scan=None) -> Measurements:
    """The volume in ml of every structure (non-zero value) of ``labels`` (a ``core.LabelMap``), in value order.

    A voxel's volume is ``|det|`` of the affine's 3x3 part (mm³; 1 ml = 1000 mm³), so an oblique or sheared grid
    counts right. ``scan`` (a Volume) names the scan the labels belong to; by default the label map's source.
    """
    data = np.asarray(labels.data)
    counts = np.bincount(data.ravel())
    voxel_mm3 = abs(float(np.linalg.det(labels.affine[:3, :3])))
    names = getattr(labels, "names", {}) or {}
    where = Scan.of(scan if scan is not None else labels)
    return Measurements(LabelVolume(value=int(v), label=str(names.get(int(v), "")), voxels=int(counts[v]),
                                    ml=counts[v] * voxel_mm3 / 1000.0, scan=where)
                        for v in np.flatnonzero(counts) if v != 0)
