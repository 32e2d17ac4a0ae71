"""VMTK's aorta CTA: the maximum inscribed sphere radius along both iliac paths against VMTK's own
``MaximumInscribedSphereRadius`` on its reference centerlines: from the lumen volumen grows itself between the
reference centerlines' ends, and from the reference lumen surface's voxels (a second check)."""

from __future__ import annotations

import numpy as np
import pytest

from volumen.data import shared_data, shared_data_candidates


@pytest.fixture(scope="module")
def aorta():
    """``(volume, [(points, radius), ...])``: the scan and VMTK's two centerlines with their radii."""
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy

    import volumen

    found = shared_data("vmtk-aorta", "aorta.mha")
    if found is None:
        pytest.skip(f"VMTK aorta data not found (set VOLUMEN_SHARED_DATA; looked in "
                    f"{', '.join(map(str, shared_data_candidates()))})")
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(str(found.parent / "aorta-centerline.vtp"))
    reader.Update()
    pd = reader.GetOutput()
    pts = vtk_to_numpy(pd.GetPoints().GetData()).astype(float)
    radius = vtk_to_numpy(pd.GetPointData().GetArray("MaximumInscribedSphereRadius")).astype(float)
    off = vtk_to_numpy(pd.GetLines().GetOffsetsArray())
    con = vtk_to_numpy(pd.GetLines().GetConnectivityArray())
    lines = [(pts[con[a:b]], radius[con[a:b]]) for a, b in zip(off[:-1], off[1:], strict=True)]
    return volumen.load(found), lines


@pytest.fixture(scope="module")
def reference_lumen(aorta):
    """The voxels inside VMTK's lumen surface (within its box, which holds both paths)."""
    from tests.endoscopy.aorta_data import Surface

    vol = aorta[0]
    surf = Surface(shared_data("vmtk-aorta", "aorta.mha").parent)
    zyx, inside = surf.voxels(vol)
    mask = np.zeros(vol.shape, bool)
    mask[tuple(zyx[inside].T)] = True
    return mask


def _errors(profile, points, radius) -> np.ndarray:
    """|ours - VMTK's| at each of VMTK's points, ours read at the arc of our centerline nearest it."""
    arc = np.array([profile.centerline.project(p)[0] for p in points])
    return np.abs(np.interp(arc, profile.centerline.arc, profile.sections.inscribed_radius) - radius)


@pytest.mark.parametrize("source", ["grown", "surface"])
@pytest.mark.parametrize("line", [0, 1], ids=["iliac-a", "iliac-b"])
def test_inscribed_sphere_radius_matches_vmtk(aorta, reference_lumen, source, line):
    """Median within 0.5 mm, 90th percentile within 1.0 mm, along the whole path from the aorta into the iliac."""
    from volumen.analysis import profile

    vol, lines = aorta
    points, radius = lines[line]
    lumen = reference_lumen if source == "surface" else None
    p = profile(vol, points[0], points[-1], lumen=lumen)
    err = _errors(p, points, radius)
    print(f"{source} line {line}: {len(err)} points, median {np.median(err):.3f} mm, "
          f"p90 {np.percentile(err, 90):.3f} mm, length {p.length:.1f} mm")
    assert np.median(err) <= 0.5 and np.percentile(err, 90) <= 1.0
