"""VMTK's public aorta CTA with its reference centerline and lumen surface (shared/data/vmtk-aorta).

Found by :func:`volumen.data.shared_data` (``VOLUMEN_SHARED_DATA``, or ``shared/data`` beside
the repository or beside its folder). The reference files are in volumen's
world coordinates (the folder's README says how).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from volumen.data import shared_data, shared_data_candidates

START = (222.1, 175.9, 21.7)  # in the aorta, VMTK's centerlines' common start
ENDS = {"right iliac": (234.4, 101.3, 29.0), "left iliac": (210.2, 103.0, 31.7)}


def aorta_folder() -> Path:
    """The aorta's folder, or a pytest skip naming where it was looked for."""
    found = shared_data("vmtk-aorta", "aorta.mha")
    if found is None:
        pytest.skip(f"VMTK aorta data not found (set VOLUMEN_SHARED_DATA; looked in "
                    f"{', '.join(map(str, shared_data_candidates()))})")
    return found.parent


def reference_lines(folder: Path) -> list[np.ndarray]:
    """VMTK's two centerlines (aorta -> each iliac), (n, 3) world mm, zero-length segments dropped."""
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy

    r = vtk.vtkXMLPolyDataReader()
    r.SetFileName(str(folder / "aorta-centerline.vtp"))
    r.Update()
    pd = r.GetOutput()
    pts = vtk_to_numpy(pd.GetPoints().GetData()).astype(float)
    off = vtk_to_numpy(pd.GetLines().GetOffsetsArray())
    con = vtk_to_numpy(pd.GetLines().GetConnectivityArray())
    lines = []
    for a, b in zip(off[:-1], off[1:], strict=True):
        p = pts[con[a:b]]
        keep = np.concatenate([[True], np.linalg.norm(np.diff(p, axis=0), axis=1) > 1e-9])
        lines.append(p[keep])
    return lines


class Surface:
    """VMTK's closed lumen surface: inside tests by VTK (vtkSelectEnclosedPoints), its bounding box."""

    def __init__(self, folder: Path):
        import vtk

        s = vtk.vtkSTLReader()
        s.SetFileName(str(folder / "aorta-surface.stl"))
        s.Update()
        self.poly = s.GetOutput()
        b = np.array(self.poly.GetBounds())
        self.lo, self.hi = b[0::2], b[1::2]

    def in_box(self, points) -> np.ndarray:
        p = np.atleast_2d(points)
        return np.all((p >= self.lo) & (p <= self.hi), axis=1)

    def inside(self, points) -> np.ndarray:
        import vtk
        from vtk.util.numpy_support import numpy_to_vtk, vtk_to_numpy

        vp = vtk.vtkPoints()
        vp.SetData(numpy_to_vtk(np.ascontiguousarray(np.atleast_2d(points), float)))
        pd = vtk.vtkPolyData()
        pd.SetPoints(vp)
        sel = vtk.vtkSelectEnclosedPoints()
        sel.SetInputData(pd)
        sel.SetSurfaceData(self.poly)
        sel.Update()
        return vtk_to_numpy(sel.GetOutput().GetPointData().GetArray("SelectedPoints")).astype(bool)

    def voxels(self, volume) -> tuple[np.ndarray, np.ndarray]:
        """``(zyx, inside)``: the voxels of ``volume`` whose centres lie in the surface's box, and which are inside."""
        lo = np.floor(volume.world_to_index(self.lo)).astype(int)
        hi = np.ceil(volume.world_to_index(self.hi)).astype(int)
        lo, hi = np.minimum(lo, hi).clip(0), np.maximum(lo, hi)
        grids = np.meshgrid(*[np.arange(a, b + 1) for a, b in zip(lo[::-1], hi[::-1], strict=True)], indexing="ij")
        zyx = np.stack([g.ravel() for g in grids], axis=1)
        zyx = zyx[np.all(zyx < volume.shape, axis=1)]
        world = volume.index_to_world(zyx[:, ::-1].astype(float))
        keep = self.in_box(world)
        return zyx[keep], self.inside(world[keep])


def looking_down(img) -> float:
    """Median depth of the picture's centre (middle 20 % box) over that of its border (outer 10 %); no hit = 1 m."""
    d = np.where(np.isfinite(img.depth), img.depth, 1e3)
    h, w = d.shape
    c = d[int(0.4 * h):int(0.6 * h), int(0.4 * w):int(0.6 * w)]
    bh, bw = max(int(0.1 * h), 1), max(int(0.1 * w), 1)
    border = np.concatenate([d[:bh].ravel(), d[-bh:].ravel(), d[:, :bw].ravel(), d[:, -bw:].ravel()])
    return float(np.median(c) / np.median(border))
