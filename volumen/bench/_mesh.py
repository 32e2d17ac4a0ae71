"""``volumen bench mesh``: marching cubes on real scans and phantoms against VTK's flying edges and scikit-image.

Cases (data set, level):

- the VMTK aorta CTA (``../shared/data/vmtk-aorta/aorta.mha``, scanner units 0..2570:
  soft tissue 200-300, contrast lumen 1600-2200; no bone in this crop) upsampled with
  ``scipy.ndimage.zoom`` (order 1) to 244x202x224 and 366x303x336 voxels (x, y, z) int16,
  the sizes of a large abdominal CT. Levels: 800, where the brightest structures
  (contrast-filled vessels down to the smallest branches) come out as many small fragments
  the way bone does in CT at 300 HU (299 connected components in the original scan), and
  1100, the lumen wall (half-way between soft tissue and contrast);
- an MRI template (``volumen.data.sample("mni-brain")``, uint8) at its Otsu level;
- the head and torso phantoms (``volumen.data.phantom``, int16 HU) at 300 HU (bone);
- or instead, scan files of the user's (``--scan``; ``_datasets.read_scan``) at the aorta's two sizes: a CT at
  300 HU (bone), another scan at its Otsu level.

Every implementation meshes the same array with the same spacing in the same process:
ours (``volumen.surface.marching_cubes``, vertices and normals, no voxel coordinates),
``vtkFlyingEdges3D`` (normals on, scalars off, vtkSMPTools ``STDThread`` backend with as
many workers as Numba has threads) and ``skimage.measure.marching_cubes`` (Lewiner, one
thread). Rounds alternate (ours, VTK, scikit-image, ours, ...) after one untimed warm-up
each; the table gives medians and the spread (lowest to highest of the timed rounds), the
time ratios, and each one's triangle and vertex counts, so a reader can see they extract
the same surface. Other processes on the machine slow every implementation alike within
a round; the load average is printed with the table.
"""

from __future__ import annotations

import os
import time

import numpy as np

from ._datasets import aorta_path, upsampled_aorta
from ._table import Table

__all__ = ["bench_mesh", "AORTA_SIZES", "AORTA_LEVELS"]

#: (nx, ny, nz) of the upsampled aorta, as in a large abdominal CT
AORTA_SIZES = {"aorta-244x202x224": (244, 202, 224), "aorta-366x303x336": (366, 303, 336)}
#: level name -> scanner units (see the module docstring)
AORTA_LEVELS = {"vessels (bone-like fragments)": 800.0, "lumen wall": 1100.0}
PHANTOMS = {"head-phantom-256": "head", "torso-phantom-256": "torso"}
QUICK_AORTA = {"aorta-61x50x56": (61, 50, 56)}


def _cases(quick: bool, progress):
    """``(name, volume, level name, level)`` for each case whose data is present (missing ones are reported)."""
    from volumen.data import phantom

    if aorta_path() is None:
        progress("VMTK aorta not found (set VOLUMEN_SHARED_DATA): aorta cases skipped")
    else:
        for name, size in (QUICK_AORTA if quick else AORTA_SIZES).items():
            vol = upsampled_aorta(size)
            for lname, level in AORTA_LEVELS.items():
                yield name, vol, lname, level
    try:
        from skimage.filters import threshold_otsu

        from volumen.data import sample

        mri = sample("mni-brain")
        if quick:
            mri.data = np.ascontiguousarray(mri.data[::4, ::4, ::4])
        yield "mri-template (mni-brain)", mri, "Otsu", float(threshold_otsu(mri.data[mri.data > 0]))
    except Exception as exc:  # noqa: BLE001 - an optional system package: report why and go on
        progress(f"MRI template skipped: {exc}")
    for name, kind in PHANTOMS.items():
        size = 48 if quick else 256
        yield name.replace("256", str(size)), phantom(kind, size=size), "bone", 300.0


def _implementations(vol, level: float, threads: int):
    """name -> callable returning ``(triangles, vertices)``; VTK's is missing without VTK."""
    from skimage.measure import marching_cubes as sk_marching_cubes

    from volumen.surface import marching_cubes
    from volumen.surface._bench import _vtk_flying_edges

    spacing = tuple(float(s) for s in vol.spacing)

    def ours():
        m = marching_cubes(vol, level, voxel_coordinates=False)
        return m.n_faces, m.n_vertices

    def skimage():
        v, f, _n, _s = sk_marching_cubes(vol.data, level, spacing=spacing)
        return len(f), len(v)

    impls = {"ours": ours}
    fe = _vtk_flying_edges(np.ascontiguousarray(vol.data), level, threads, spacing)
    if fe is not None:
        impls["vtk"] = lambda: (fe(), fe.output().GetNumberOfPoints())
    impls["skimage"] = skimage
    return impls


def _vtk_backend() -> str:
    try:
        import vtk
    except ImportError:
        return "(no VTK)"
    return vtk.vtkSMPTools.GetBackend()


def _timed_rounds(impls: dict, rounds: int) -> dict:
    """Alternating rounds after one warm-up each: name -> (counts, list of seconds)."""
    counts = {k: fn() for k, fn in impls.items()}
    times = {k: [] for k in impls}
    for _ in range(rounds):
        for k, fn in impls.items():
            t0 = time.perf_counter()
            fn()
            times[k].append(time.perf_counter() - t0)
    return {k: (counts[k], times[k]) for k in impls}


def _row(name, vol, lname, level, results) -> dict:
    row = dict(data=name, dtype=str(vol.data.dtype), level=f"{lname} {level:g}")
    med = {k: float(np.median(t)) for k, (_c, t) in results.items()}
    for k, ((tris, verts), t) in results.items():
        row.update({f"{k}_ms": 1e3 * med[k], f"{k}_spread": f"{1e3 * min(t):.1f}-{1e3 * max(t):.1f}",
                    f"{k}_tris": tris, f"{k}_verts": verts})
    for k in ("vtk", "skimage"):
        if k in med:
            row[f"ours_over_{k}"] = med["ours"] / med[k]
    return row


def _scan_cases(scans, quick: bool, progress):
    """``(name, volume, level name, level)`` of each scan (``_datasets.read_scan``) at each size: bone (300 HU) in
    a CT, else Otsu; a level past the data's range is skipped, saying so."""
    from skimage.filters import threshold_otsu

    from ._datasets import load_dataset, scan_datasets

    sizes = (QUICK_AORTA if quick else AORTA_SIZES).values()
    for name, spec in scan_datasets(scans, sizes).items():
        vol, offset = load_dataset(*spec)
        lname, level = ("bone", 300.0 + offset) if offset is not None else (
            "Otsu", float(threshold_otsu(vol.data[::2, ::2, ::2])))
        if not vol.data.min() < level < vol.data.max():
            progress(f"{name}: no surface at {lname} {level:g} (values {vol.data.min()}..{vol.data.max()}): skipped")
            continue
        yield name, vol, lname, level


def bench_mesh(*, quick: bool = False, rounds: int | None = None, with_vtk: bool = True, progress=print,
               scans=()) -> Table:
    """Run the benchmark; returns the :class:`Table` (print ``table.render()``, save with ``table.save``).

    Parameters
    ----------
    quick : bool
        Small volumes (a 61x50x56 aorta, the MRI at a quarter, 48-voxel phantoms) and two rounds.
    rounds : int, optional
        Timed rounds per case (default 7, quick 2).
    with_vtk : bool
        Run VTK's flying edges when VTK is installed.
    scans : sequence of (Volume, offset)
        Scans of the user's (``_datasets.read_scan``), meshed instead of the benchmark's data (:func:`_scan_cases`).
    """
    import numba

    threads = numba.get_num_threads()
    rounds = rounds or (2 if quick else 7)
    table = Table(f"volumen bench mesh (marching cubes; ours and VTK on {threads} threads)", [
        ("data", "data", "s"), ("dtype", "dtype", "s"), ("level", "level", "s"),
        ("ours_ms", "ours ms", ".1f"), ("ours_spread", "ours min-max", "s"),
        ("vtk_ms", "VTK ms", ".1f"), ("vtk_spread", "VTK min-max", "s"), ("ours_over_vtk", "ours/VTK", ".2f"),
        ("skimage_ms", "skimage ms", ".1f"), ("ours_over_skimage", "ours/skimage", ".2f"),
        ("ours_tris", "triangles ours", "d"), ("vtk_tris", "VTK", "d"), ("skimage_tris", "skimage", "d"),
        ("ours_verts", "vertices ours", "d"), ("vtk_verts", "VTK", "d"), ("skimage_verts", "skimage", "d"),
    ])
    load0 = os.getloadavg()
    for name, vol, lname, level in (_scan_cases(scans, quick, progress) if scans else _cases(quick, progress)):
        impls = _implementations(vol, level, threads)
        if not with_vtk:
            impls.pop("vtk", None)
        row = table.add(**_row(name, vol, lname, level, _timed_rounds(impls, rounds)))
        progress(f"{name} {vol.shape[::-1]} (x, y, z) at {level:g}: ours {row['ours_ms']:.1f} ms"
                 + (f", VTK {row['vtk_ms']:.1f} ms" if "vtk_ms" in row else "")
                 + f", scikit-image {row['skimage_ms']:.1f} ms")
    table.notes.append(f"median of {rounds} alternating rounds (ours, VTK, scikit-image) after a warm-up each; "
                       "min-max: the fastest and slowest round; ratios < 1: ours faster")
    table.notes.append(f"ours: {threads} worker threads (numba.get_num_threads()); vtkFlyingEdges3D: "
                       f"vtkSMPTools {_vtk_backend()} backend, {threads} threads, normals on; "
                       "scikit-image: Lewiner, 1 thread")
    table.notes.append("counts: ours and VTK one vertex per crossed edge (ours adds one inside the few cubes whose "
                       "contour cannot be triangulated otherwise); scikit-image likewise welded")
    table.notes.append(f"load average (1 min) {load0[0]:.2f} at the start, {os.getloadavg()[0]:.2f} at the end "
                       f"on {os.cpu_count()} CPUs")
    return table
