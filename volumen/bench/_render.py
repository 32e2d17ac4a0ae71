"""``volumen bench render``: ray-casting speed per volume size, image size, mode and shading, against VTK.

For each case the table gives the median frame time, samples per second, and
for composite modes the speed-up from empty-space skipping and early ray
termination (the same frame rendered with both switched off). When ``vtk`` is
installed, the composite cases are also rendered by VTK's fixed-point CPU
mapper in the same run (same volume, camera, sample distance, transfer
function, image size, all threads), with the time ratio ours / VTK and the
mean absolute difference of the two pictures (RGB in [0, 1]).
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from ._table import Table, median_time, resolve_device
from ._vtk import VtkScene, vtk_available

__all__ = ["bench_render", "CASES", "VOLUMES", "IMAGES"]

#: (nz, ny, nx) of the head phantom
VOLUMES = {"128^3": (128, 128, 128), "256^3": (256, 256, 256), "512x512x256": (256, 512, 512)}
IMAGES = {"512x512": (512, 512), "782x415": (782, 415)}
#: (mode, shading, preset)
CASES = [
    ("composite", "none", "ct-bone"),
    ("composite", "headlight", "ct-bone"),
    ("composite", "headlight", "ct-skin-bone"),
    ("mip", "none", None),
    ("minip", "none", None),
    ("average", "none", None),
    ("isosurface", "headlight", None),
]
QUICK = {"volumes": {"64^3": (64, 64, 64)}, "images": {"128x128": (128, 128)}}


def _scene(volume, mode, shading, preset, spv):
    from volumen.core import Isosurface, Sampling, Scene, Shading, TransferFunction
    from volumen.render import default_transfer

    tf = TransferFunction.preset(preset) if preset else default_transfer(volume, mode)
    return Scene(volume=volume, volume_ref="phantom:head", transfer=tf, mode=mode,
                 shading=Shading(mode=shading), sampling=Sampling(samples_per_voxel=spv),
                 isosurface=Isosurface(value=300.0))


def _rgb(image) -> np.ndarray:
    return np.clip(image.rgba[..., :3], 0.0, 1.0)


def bench_render(*, volumes=None, images=None, cases=None, spv: float = 1.0, repeat: int = 3,
                 with_vtk: bool = True, backend: str = "cpu", progress=print) -> Table:
    """Run the benchmark; returns the :class:`Table` (print ``table.render()``, save with ``table.save``).

    Parameters
    ----------
    volumes : dict name -> (nz, ny, nx), optional
        Head phantom sizes (default :data:`VOLUMES`).
    images : dict name -> (width, height), optional
        Image sizes (default :data:`IMAGES`).
    cases : list of (mode, shading, preset), optional
    spv : float
        Samples per voxel.
    repeat : int
        Timed frames per case (median reported) after one warm-up frame.
    with_vtk : bool
        Also render composite cases with VTK when it is installed.
    backend : {"cpu", "cuda", "auto"}
        Our renderer's backend; ``cuda`` fails at once (``CudaUnavailableError``) where no device is usable.
    """
    from volumen.core import Camera
    from volumen.data import phantom
    from volumen.render import render

    volumes = volumes or VOLUMES
    images = images or IMAGES
    cases = cases or CASES
    backend, device = resolve_device(backend)
    use_vtk = with_vtk and vtk_available()
    table = Table(f"volumen bench render ({device} ray casting; head phantom, anterior view)", [
        ("volume", "volume", "s"), ("image", "image", "s"), ("mode", "mode", "s"), ("shading", "shading", "s"),
        ("preset", "preset", "s"), ("ms", "ms/frame", ".1f"), ("fps", "fps", ".2f"),
        ("msamples_s", "Msamples/s", ".0f"), ("skip_speedup", "ESS+ERT speed-up", ".2f"),
        ("vtk_ms", "VTK ms", ".1f"), ("ratio_vtk", "ours/VTK", ".2f"), ("diff_vtk", "mean |diff| vs VTK", ".4f"),
    ])
    table.notes.append(f"samples per voxel {spv}; median of {repeat} frames after a warm-up frame; "
                       "Numba kernels compiled before timing")
    if not use_vtk:
        table.notes.append("VTK not installed (pip install 'volumen[bench]'): no peer columns")
    for vname, shape in volumes.items():
        t0 = time.perf_counter()
        vol = phantom("head", size=shape)
        progress(f"[{vname}] head phantom {shape[::-1]} (x, y, z) in {time.perf_counter() - t0:.1f} s")
        for iname, size in images.items():
            camera = Camera.orbit(vol, view="anterior")
            for mode, shading, preset in cases:
                scene = _scene(vol, mode, shading, preset, spv)
                image = render(scene, camera, size, device=backend)  # warm-up: JIT, per-volume caches
                ms = median_time(lambda: render(scene, camera, size, device=backend), repeat=repeat, warmup=0) * 1e3
                samples = float(np.sum(image.stats.get("samples", 0)))
                row = table.add(volume=vname, image=iname, mode=mode, shading=shading,
                                preset=preset or "-", ms=ms, fps=1e3 / ms, msamples_s=samples / ms * 1e-3)
                if mode in ("composite", "isosurface"):
                    plain = replace(scene, sampling=replace(scene.sampling, skip_empty=False, early_termination=1.0))
                    render(plain, camera, size, device=backend)
                    ms_plain = median_time(lambda: render(plain, camera, size, device=backend), repeat=1,
                                           warmup=0) * 1e3
                    row["skip_speedup"] = ms_plain / ms
                if use_vtk and mode == "composite":
                    peer = VtkScene(scene, camera, size)
                    theirs = peer.render()
                    row["vtk_ms"] = median_time(peer.render_only, repeat=repeat, warmup=0) * 1e3
                    row["ratio_vtk"] = ms / row["vtk_ms"]
                    row["diff_vtk"] = float(np.mean(np.abs(_rgb(image) - theirs)))
                progress(f"  {iname} {mode}/{shading}/{preset or '-'}: {ms:.1f} ms"
                         + (f", VTK {row['vtk_ms']:.1f} ms" if "vtk_ms" in row else ""))
    return table
