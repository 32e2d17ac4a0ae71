"""``volumen bench techniques``: meshes, ray casting and texture slicing along one scripted camera path.

For each phantom (the head; a 512x512x124 torso):

1. mesh generation at 300 HU: our marching cubes against scikit-image's and
   VTK's flying edges (time, triangles), plus the colleague's gyroid benchmark
   (``volumen.surface._bench.bench_marching_cubes``) in the same run;
2. a camera path of 120 frames -- an orbit (60 frames, 6 degrees apart) and a
   fly-in from outside to inside the volume (60 frames, perspective) --
   rendered by the mesh, by ray casting and by texture slicing (1 and 2
   samples per voxel, with and without shading, each adaptive plane
   distribution, reduced viewports of 1/2 and 1/4). Per case: mean frame time
   and the frame-time-weighted mean ``sum t^2 / sum t`` (penalises stutter).
   OpenGL timings include ``glFinish``; here OpenGL may be Mesa's llvmpipe
   (software), which the table's notes say;
3. agreement: orthographic slicing against ray casting of the same scene
   (mean |rgba difference|; target < 0.02).
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from ._table import Table, machine_info

__all__ = ["bench_techniques", "camera_path", "QUICK", "main"]

VOLUMES = {"head": ("head", None), "torso 512x512x124": ("torso", (124, 512, 512))}
QUICK = {"volumes": {"head 48": ("head", 48)}, "size": (64, 64), "frames": 12, "mc_sizes": (32,)}


def camera_path(volume, frames: int = 120):
    """``frames`` cameras: the first half an orbit (elevation 15 degrees), the second a perspective
    fly-in along the anterior axis from twice the framing distance to 0.3 of the volume's radius inside."""
    from volumen.core import Camera

    n_orbit = frames // 2
    cams = [Camera.orbit(volume, azimuth=360.0 * i / n_orbit, elevation=15.0) for i in range(n_orbit)]
    start = Camera.orbit(volume, view="anterior")
    c = np.asarray(volume.center)
    back = np.asarray(start.position) - c
    back /= np.linalg.norm(back)
    radius = volume.diagonal / 2
    for s in np.linspace(0.0, 1.0, frames - n_orbit):
        d = (1 - s) * start.distance + s * (-0.3 * radius)
        eye = c + back * d
        cams.append(Camera(position=tuple(eye), target=tuple(eye - back * radius), up=start.up, fov=50.0))
    return cams


def _frame_times(fn, cams) -> dict:
    fn(cams[0])  # warm-up: compilation, texture upload
    t = []
    for cam in cams:
        t0 = time.perf_counter()
        fn(cam)
        t.append(time.perf_counter() - t0)
    t = np.asarray(t)
    return {"frames": len(t), "mean_ms": 1e3 * t.mean(), "weighted_ms": 1e3 * (t ** 2).sum() / t.sum(),
            "max_ms": 1e3 * t.max()}


def _mc_rows(table, name, volume, iso):
    from skimage.measure import marching_cubes as sk_mc

    from volumen.surface import marching_cubes
    from volumen.surface._bench import _vtk_flying_edges

    data = np.ascontiguousarray(volume.data, np.float32)
    marching_cubes(volume, iso, voxel_coordinates=False)
    for impl, fn in (("volumen", lambda: marching_cubes(volume, iso, voxel_coordinates=False).n_faces),
                     ("scikit-image", lambda: len(sk_mc(data, iso)[1])),
                     ("vtkFlyingEdges3D", _vtk_flying_edges(data, iso, 2) or (lambda: None))):
        t0 = time.perf_counter()
        tris = fn()
        table.add(volume=name, implementation=impl, ms=1e3 * (time.perf_counter() - t0), triangles=tris)


def _cases(base, size, gl: bool, planes) -> list:
    """(technique, case, function of a camera) rows of the frame-time table for the scene ``base``."""
    from volumen.core import Sampling, Shading
    from volumen.render import render, render_reduced

    def frame(scene=base, fraction=1.0, **how):
        return lambda c: render_reduced(scene, c, size, fraction, **how)

    cases = [("mesh", "phong", frame(technique="mesh"))] if gl else []
    cases.append(("raycast", "headlight spv 1", lambda c: render(base, c, size)))
    cases += [("raycast", f"headlight reduced 1/{int(1 / f)}", frame(fraction=f)) for f in (0.5, 0.25)]
    if not gl:
        return cases
    for spv in (1.0, 2.0):
        for sh in ("none", "headlight"):
            sc = base.with_(shading=Shading(mode=sh), sampling=Sampling(samples_per_voxel=spv))
            cases.append(("slicing", f"{sh} spv {spv:g}", frame(sc, technique="slicing", depth=False)))
    cases.append(("slicing", "headlight spv 1 + depth", frame(technique="slicing")))
    cases += [("slicing", f"headlight {p}", frame(technique="slicing", depth=False, planes=p)) for p in planes[1:]]
    cases += [("slicing", f"headlight reduced 1/{int(1 / f)}", frame(fraction=f, technique="slicing"))
              for f in (0.5, 0.25)]
    return cases


def bench_techniques(*, volumes=None, size=(256, 256), frames: int = 120, mc_sizes=(128,), progress=print):
    """Run the benchmark; returns ``(mc_table, frames_table, agreement_table)`` (:class:`Table` each).

    Parameters
    ----------
    volumes : dict label -> (phantom name, size), optional
    size : (width, height) of the frames, pixels
    frames : int
        Length of the camera path (half orbit, half fly-in).
    mc_sizes : tuple of int
        Gyroid cube sizes of ``bench_marching_cubes``.
    """
    from volumen.core import Camera, Isosurface, Sampling, Scene, Shading, TransferFunction
    from volumen.data import phantom
    from volumen.render import option_choices, render
    from volumen.render.raster import RasterUnavailable, context_info
    from volumen.surface._bench import bench_marching_cubes

    volumes = volumes or VOLUMES
    mc = Table("marching cubes at 300 HU (single run) and on gyroid cubes (median)",
               [("volume", "volume", "s"), ("implementation", "implementation", "s"), ("ms", "ms", ".1f"),
                ("triangles", "triangles", "d")])
    ft = Table(f"frame times along a {frames}-frame path (orbit + fly-in), {size[0]}x{size[1]}",
               [("volume", "volume", "s"), ("technique", "technique", "s"), ("case", "case", "s"),
                ("frames", "frames", "d"), ("mean_ms", "mean ms", ".1f"), ("weighted_ms", "sum t^2/sum t ms", ".1f"),
                ("max_ms", "max ms", ".1f")])
    ag = Table("orthographic slicing vs ray casting, same scene (target: mean |diff| < 0.02)",
               [("volume", "volume", "s"), ("shading", "shading", "s"), ("spv", "spv", ".0f"),
                ("mad", "mean |diff|", ".4f"), ("max", "max |diff|", ".3f")])
    for r in bench_marching_cubes(sizes=mc_sizes, repeats=3):
        for impl, key in (("volumen", "ours"), ("scikit-image", "skimage"), ("vtkFlyingEdges3D", "vtk")):
            mc.add(volume=f"gyroid {r['size']}^3", implementation=impl, ms=r[f"{key}_ms"],
                   triangles=r[f"{key}_triangles"])
    try:
        info = context_info()
        ft.notes.append(f"OpenGL: {info['GL_RENDERER']} ({info['GL_VERSION']}); slicing without depth read-backs "
                        "unless the case says so; times include glFinish")
        gl = True
    except RasterUnavailable as exc:
        ft.notes.append(f"no OpenGL context ({exc}): mesh and slicing rows skipped")
        gl = False
    tf = TransferFunction.preset("ct-bone")
    for label, (pname, psize) in volumes.items():
        t0 = time.perf_counter()
        vol = phantom(pname, size=psize)
        progress(f"{label}: {vol.shape} generated in {time.perf_counter() - t0:.1f} s")
        _mc_rows(mc, label, vol, 300.0)
        cams = camera_path(vol, frames)
        base = Scene(volume=vol, transfer=tf, isosurface=Isosurface(value=300.0), shading=Shading(mode="headlight"))
        cases = _cases(base, size, gl, option_choices("slicing")["planes"])
        for tech, case, fn in cases:
            row = ft.add(volume=label, technique=tech, case=case, **_frame_times(fn, cams))
            progress(f"  {tech:12s} {case:28s} mean {row['mean_ms']:8.1f} ms  weighted {row['weighted_ms']:8.1f} ms")
        if gl:
            for sh in ("none", "headlight"):
                for spv in (1.0, 2.0):
                    sampling = Sampling(samples_per_voxel=spv, jitter=False, skip_empty=False, early_termination=1.0)
                    sc = base.with_(shading=Shading(mode=sh), sampling=sampling)
                    cam = Camera.orbit(vol, azimuth=30, elevation=10, projection="orthographic")
                    a, b = render(sc, cam, size), render(sc, cam, size, technique="slicing")
                    d = np.abs(a.rgba - b.rgba)
                    ag.add(volume=label, shading=sh, spv=spv, mad=float(d.mean()), max=float(d.max()))
    mc.notes.append(f"machine: {machine_info().get('cpus')} CPUs; VTK on 2 STDThread workers for the phantoms")
    return mc, ft, ag


def main(args) -> int:
    """Entry of ``volumen bench techniques`` (``--quick``: a 48-voxel head, 64x64, 12 frames)."""
    kw = dict(QUICK) if args.quick else {}
    tables = bench_techniques(**kw)
    stem = "techniques" + ("-quick" if args.quick else "")
    for name, table in zip(("mc", "frames", "agreement"), tables, strict=True):
        print()
        print(table.render())
        path = table.save(Path(args.out) / f"{stem}-{name}.json")
        print(f"wrote {path}")
    return 0
