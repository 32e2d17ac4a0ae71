"""``volumen bench render --device gl``: the OpenGL ray caster against VTK's GPU ray caster on the same OpenGL.

Both run in this process on the machine's OpenGL (Mesa llvmpipe without a GPU,
through EGL for both): ours through ``volumen.render.render(device="gl")``
(the frame packed by the shared Python code, one fragment-shader pass, float
read-back), VTK's ``vtkGPUVolumeRayCastMapper`` (``vtkOpenGLGPUVolumeRayCastMapper``)
drawing the same scene offscreen (:class:`~._vtk_peer.VtkScene` with its mapper
swapped: same volume, transfer function points, sample distance, trilinear
interpolation, headlight Phong, camera, image size). Timings are medians of
alternating rounds after a warm-up frame (textures uploaded, shaders compiled),
so both see the same machine load. The peer renders composite mode only; the
other modes (mip, isosurface, lit models) are timed for ours, with the CPU ray
caster beside them.
"""

from __future__ import annotations

import numpy as np

from ._render import _alternate, _scene, load_dataset
from ._table import Table
from ._vtk_peer import VtkScene, vtk_available

__all__ = ["bench_render_gl", "GL_CASES", "GL_DATASETS", "vtk_gpu_scene"]

#: (mode, shading, preset): the issue's case first (composite + headlight), then the other modes
GL_CASES = [
    ("composite", "headlight", "ct-bone"),
    ("composite", "headlight", "ct-skin-bone"),
    ("composite", "none", "ct-bone"),
    ("mip", "none", None),
    ("isosurface", "headlight", None),
    ("composite", "shadows", "ct-bone"),
]
GL_DATASETS = {"head-phantom-256": ("head", (256, 256, 256)), "aorta-244x202x224": ("aorta", (244, 202, 224))}
GL_QUICK = {"datasets": {"head-phantom-64": ("head", (64, 64, 64))}, "images": {"128x128": (128, 128)}}


def vtk_gpu_scene(scene, camera, size) -> VtkScene:
    """:class:`VtkScene` drawing with ``vtkGPUVolumeRayCastMapper`` instead of the fixed-point CPU mapper."""
    import vtk

    peer = VtkScene(scene, camera, size)
    actor = peer._ren.GetVolumes().GetItemAsObject(0)
    cpu = actor.GetMapper()
    gpu = vtk.vtkGPUVolumeRayCastMapper()
    gpu.SetInputData(cpu.GetInput())
    gpu.AutoAdjustSampleDistancesOff()
    gpu.LockSampleDistanceToInputSpacingOff()
    gpu.SetSampleDistance(cpu.GetSampleDistance())
    actor.SetMapper(gpu)
    return peer


def _lights(scene, camera):
    from volumen.core import Light

    r, u, f = camera.basis()
    c, d = np.asarray(scene.volume.center), scene.volume.diagonal
    return scene.with_(lights=(Light(position=tuple(c + d * (0.8 * r + 0.7 * u - 0.6 * f)), intensity=1.0),))


def _case(table, scene, camera, size, rounds, use_vtk, label):
    from volumen.render import render

    image = render(scene, camera, size, device="gl")  # warm-up: shader compiled, textures uploaded
    peer = theirs = None
    if use_vtk and scene.mode == "composite" and scene.shading.mode in ("none", "headlight"):
        try:
            peer = vtk_gpu_scene(scene, camera, size)
        except ValueError as exc:  # a grid VTK's mapper is not given (the CPU bench does the same)
            table.notes.append(f"{label['dataset']}: no VTK peer ({exc})")
        else:
            theirs = peer.render()
    ours_s, vtk_s = _alternate(lambda: render(scene, camera, size, device="gl"),
                               None if peer is None else peer.render_only, rounds)
    render(scene, camera, size, device="cpu")
    cpu_s, _ = _alternate(lambda: render(scene, camera, size, device="cpu"), None, max(1, rounds // 2))
    row = table.add(**label, ms=ours_s * 1e3, cpu_ms=cpu_s * 1e3)
    if peer is not None:
        row.update(vtk_ms=vtk_s * 1e3, ratio_vtk=ours_s / vtk_s,
                   diff_vtk=float(np.mean(np.abs(np.clip(image.rgba[..., :3], 0, 1) - theirs))))
    return row


def bench_render_gl(*, datasets=None, images=None, cases=None, spv: float = 1.0, rounds: int = 5,
                    with_vtk: bool = True, progress=print) -> Table:
    """Run the benchmark; returns the :class:`Table` (print ``table.render()``, save with ``table.save``)."""
    from volumen.core import Camera
    from volumen.render.raster import context_info

    info = context_info()
    use_vtk = with_vtk and vtk_available()
    table = Table(f"volumen bench render --device gl (OpenGL ray caster vs VTK vtkGPUVolumeRayCastMapper, "
                  f"{info['GL_RENDERER']})", [
        ("dataset", "data set", "s"), ("image", "image", "s"), ("mode", "mode", "s"), ("shading", "shading", "s"),
        ("preset", "preset", "s"), ("ms", "gl ms", ".1f"), ("vtk_ms", "VTK GPU ms", ".1f"),
        ("ratio_vtk", "gl / VTK", ".2f"), ("diff_vtk", "mean |RGB diff|", ".3f"), ("cpu_ms", "cpu ms", ".1f")])
    for dname, (kind, shape, *scan) in (datasets or GL_DATASETS).items():
        vol, offset = load_dataset(kind, shape, *scan) or (None, None)
        if vol is None:
            table.notes.append(f"{dname}: not on this machine")
            continue
        camera = Camera.orbit(vol, azimuth=-30, elevation=15)
        for iname, size in (images or {"512x512": (512, 512)}).items():
            for mode, shading, preset in cases or GL_CASES:
                scene = _scene(vol, mode, shading, preset, offset, spv)
                if shading == "shadows":
                    scene = _lights(scene, camera)
                shown = (preset if offset is not None else "data default") if preset else "-"
                label = dict(dataset=dname, image=iname, mode=mode, shading=shading, preset=shown)
                row = _case(table, scene, camera, size, rounds, use_vtk, label)
                progress(f"  {dname} {iname} {mode}/{shading}/{shown}: gl {row['ms']:.1f} ms"
                         + (f", VTK GPU {row['vtk_ms']:.1f} ms, ratio {row['ratio_vtk']:.2f}"
                            if "vtk_ms" in row else ""))
    table.notes.append(f"OpenGL: {info['GL_RENDERER']}, {info['GL_VERSION']}; VTK's mapper draws on the same "
                       "Mesa driver (EGL, offscreen); medians of alternating rounds after a warm-up frame")
    if not use_vtk:
        table.notes.append("VTK not installed (or --no-vtk): no peer column")
    return table
