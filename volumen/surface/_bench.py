"""Benchmark of marching cubes: ours against scikit-image and VTK's flying edges (not a test)."""

from __future__ import annotations

import os
import time

import numpy as np

from ._marching_cubes import marching_cubes

__all__ = ["bench_volume", "bench_marching_cubes"]


def bench_volume(n: int) -> np.ndarray:
    """A smooth ``(n, n, n)`` float32 gyroid with four periods per axis (level 0 cuts it in two)."""
    g = np.linspace(0.0, 8.0 * np.pi, n, dtype=np.float32)
    z, y, x = g[:, None, None], g[None, :, None], g[None, None, :]
    return (np.sin(x) * np.cos(y) + np.sin(y) * np.cos(z) + np.sin(z) * np.cos(x)).astype(np.float32)


def _median_ms(fn, repeats: int) -> float:
    fn()  # warm up: JIT compilation, caches, thread pools
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return 1e3 * float(np.median(times))


def _vtk_flying_edges(vol: np.ndarray, level: float, threads: int, spacing=(1.0, 1.0, 1.0)):
    """A callable running vtkFlyingEdges3D (normals on, STDThread SMP backend with ``threads`` workers) on
    ``vol`` [z, y, x] with ``spacing`` (dz, dy, dx) and returning the triangle count, or None without VTK.
    Its ``output()`` gives the last output (``vtkPolyData``)."""
    try:
        import vtk
        from vtk.util import numpy_support
    except ImportError:
        return None
    smp = vtk.vtkSMPTools
    smp.SetBackend("STDThread")
    smp.Initialize(threads)
    img = vtk.vtkImageData()
    img.SetDimensions(vol.shape[2], vol.shape[1], vol.shape[0])
    img.SetSpacing(spacing[2], spacing[1], spacing[0])
    img.GetPointData().SetScalars(numpy_support.numpy_to_vtk(vol.ravel(), deep=True))
    fe = vtk.vtkFlyingEdges3D()
    fe.SetInputData(img)
    fe.SetValue(0, level)
    fe.ComputeNormalsOn()
    fe.ComputeScalarsOff()

    def run():
        fe.Modified()
        fe.Update()
        return fe.GetOutput().GetNumberOfCells()

    run.output = fe.GetOutput
    return run


def bench_marching_cubes(sizes=(128, 256), repeats: int = 5, level: float = 0.0) -> list[dict]:
    """Time marching cubes on :func:`bench_volume` cubes of each size.

    Ours runs on Numba's threads and VTK's flying edges on as many STDThread workers
    (``os.cpu_count()``); scikit-image's Lewiner marching cubes is single-threaded.
    Each time is the median of ``repeats`` runs after a warm-up run (JIT compilation
    excluded). Ours produces vertices and normals, as VTK does (no voxel coordinates).

    Returns
    -------
    list of dict
        One per size: ``size``, ``threads``, ``ours_ms``, ``ours_triangles``,
        ``skimage_ms``, ``skimage_triangles``, ``vtk_ms``, ``vtk_triangles`` (None without
        VTK), and the speed-ups ``skimage_over_ours`` and ``vtk_over_ours`` (> 1: ours faster).
    """
    import numba
    from skimage.measure import marching_cubes as sk_marching_cubes

    threads = numba.get_num_threads()
    rows = []
    for n in sizes:
        vol = bench_volume(int(n))
        ours_tris = marching_cubes(vol, level, voxel_coordinates=False).n_faces
        ours = _median_ms(lambda vol=vol: marching_cubes(vol, level, voxel_coordinates=False), repeats)
        sk_tris = len(sk_marching_cubes(vol, level)[1])
        sk = _median_ms(lambda vol=vol: sk_marching_cubes(vol, level), repeats)
        row = dict(size=int(n), threads=threads, ours_ms=round(ours, 2), ours_triangles=ours_tris,
                   skimage_ms=round(sk, 2), skimage_triangles=sk_tris, skimage_over_ours=round(sk / ours, 2),
                   vtk_ms=None, vtk_triangles=None, vtk_over_ours=None)
        fe = _vtk_flying_edges(vol, level, os.cpu_count() or 1)
        if fe is not None:
            row["vtk_triangles"] = int(fe())
            vt = _median_ms(fe, repeats)
            row.update(vtk_ms=round(vt, 2), vtk_over_ours=round(vt / ours, 2))
        rows.append(row)
    return rows


if __name__ == "__main__":
    for r in bench_marching_cubes():
        print(r)
