"""``volumen bench lighting``: the cost of shadows and scattering, in the seeds' experiment, with their figures.

The seeds measured shadow rays in a GPU ray caster: 0.09 frames per second
for a 512x512x256 CT with one light (0.04 with two) at 782x415, against 65 fps
without shadows; a later physically based variant (3 lights, 128 steps, 32
shadow steps) reached 35 fps on an RTX 2080 Ti. This benchmark renders the same
sweeps on the CPU (head phantom, ``ct-bone``, world-fixed spot lights 1.5
volume diagonals away, upper right and upper left in front):

* volume sweep: 512x512x256, 400x400x200, 200x200x100, 100x100x50 at 782x415;
* viewport sweep: 782x415, 564x300, 376x200, 188x100 on 323x323x179;
* distance sweep: eye 1, 2.5, 4, 5.5 volume diagonals from the centre (323x323x179, 782x415);

each with 1 and 2 lights, Phong against shadows (``fast``: illumination
volumes, built before timing; ``direct``: shadow rays, on the small cases).
Then the illumination-volume build time per volume, and single scattering
with 3 lights at 128 steps per ray (``direct``: 32 shadow steps per light
path) against Phong at the same steps. Frame times are medians after a
warm-up frame (which compiles the kernels and builds the volumes).

Last, CTs (:func:`real_ct_rows`): the VMTK aorta resampled to about
366x303x336, and the whole-abdomen CT built for the purpose at that size, at 782x415
with the default sample rate, in two presets: the command line's default for a CT (``ct-skin-bone``,
translucent skin and soft tissue) and the sweeps' ``ct-bone`` (the seeds' preset: the bars give its baseline,
15.0 / 8.3 / 5.1 fps, at the seeds' viewport without naming a preset, and asks for twice that). Phong and shadows with
one light and scattering with three, the camera orbiting, from the default
view and zoomed until the scan fills the picture (the phantom is mostly
empty space and flatters), each at full rate and with adaptive sampling
(``Sampling.adaptive``), beside the frame rates asked for. The
default step is the smallest voxel spacing: on the aorta's slab, resampled
from 34 slices to 336, that is 0.15 mm, which a CT acquired at that size
would not have; the rows say the step they ran at. And per CT and preset, from the default view, shadows with
one light moved 3 degrees every frame, as a user drags it: every frame sweeps its illumination volume again (the
row gives that sweep's time too).
"""

from __future__ import annotations

import time

import numpy as np

from ._table import WARMUP_FRAMES, Table, median_time, resolve_device

__all__ = ["bench_lighting", "real_ct_rows", "filling_zoom", "SEEDS", "REAL_CT"]

#: the seeds' figures (GPU)
SEEDS = {"shadows_1": 0.09, "shadows_2": 0.04, "phong": 65.0, "scattering_3": 35.0}

FULL = {
    "volumes": {"512x512x256": (256, 512, 512), "400x400x200": (200, 400, 400), "200x200x100": (100, 200, 200),
                "100x100x50": (50, 100, 100)},
    "viewports": {"782x415": (782, 415), "564x300": (564, 300), "376x200": (376, 200), "188x100": (188, 100)},
    "sweep_volume": ("323x323x179", (179, 323, 323)),
    "distances": (1.0, 2.5, 4.0, 5.5),
    "direct_max_voxels": 200 * 200 * 100,
    "scatter_volume": ("512x512x256", (256, 512, 512)),
}
#: the CT rows: data set kinds, size (x, y, z voxels; quick), viewport, frame rates asked for on 2 cores
REAL_CT = {"kinds": ("aorta", "abdomen"), "presets": ("ct-skin-bone", "ct-bone"),
           "size": (366, 303, 336), "quick_size": (46, 38, 42), "viewport": (782, 415), "quick_viewport": (98, 52),
           "bars": {"phong": 30.0, "shadows": 16.0, "scattering": 10.0}}
QUICK = {
    "volumes": {"64x64x32": (32, 64, 64), "32x32x16": (16, 32, 32)},
    "viewports": {"96x51": (96, 51), "48x26": (48, 26)},
    "sweep_volume": ("48x48x27", (27, 48, 48)),
    "distances": (1.0, 2.5),
    "direct_max_voxels": 64 * 64 * 32,
    "scatter_volume": ("64x64x32", (32, 64, 64)),
}


def _lights(volume, n, azimuth: float = 0.0):
    """``n`` spot lights (up to 3) 1.5 diagonals from the centre, upper right and upper left in front, turned by
    ``azimuth`` degrees about the volume's up axis."""
    from volumen.core import Camera, Light

    cam = Camera.orbit(volume, view="anterior", azimuth=azimuth)
    r, u, f = cam.basis()
    c = np.asarray(volume.center)
    dirs = [0.6 * r + 0.6 * u - 0.5 * f, -0.6 * r + 0.5 * u - 0.6 * f, 0.2 * r + 0.9 * u - 0.3 * f]
    out = []
    for d in dirs[:n]:
        d = d / np.linalg.norm(d)
        pos = c + 1.5 * volume.diagonal * d
        out.append(Light(position=tuple(pos), direction=tuple(-d), exponent=2.0, kind="spot", intensity=0.8))
    return tuple(out)


def _camera(volume, distance=None):
    from volumen.core import Camera

    cam = Camera.orbit(volume, view="anterior")
    if distance is None:
        return cam
    c = np.asarray(cam.target)
    back = np.asarray(cam.position) - c
    return cam.with_(position=tuple(c + back / np.linalg.norm(back) * distance * volume.diagonal))


def bench_lighting(*, quick: bool = False, repeat: int = 3, device: str = "cpu", progress=print,
                   scans=()) -> Table:
    """Run the benchmark; returns the :class:`Table` (print ``table.render()``, save with ``table.save``).

    Parameters
    ----------
    quick : bool
        Tiny sizes (:data:`QUICK`), to check the benchmark itself runs.
    repeat : int
        Timed frames per case (median reported) after one warm-up frame.
    device : {"cpu", "cuda", "auto"}
        Where the ray caster runs; ``cuda`` fails at once (``CudaUnavailableError``) where no device is usable.
    scans : sequence of (Volume, offset)
        Scans of the user's (``_datasets.read_scan``): instead of the whole benchmark, only their CT rows
        (:func:`real_ct_rows`).
    """
    from functools import partial

    from volumen.core import Scene, Shading, TransferFunction
    from volumen.data import phantom
    from volumen.render import render as render_any

    device, described = resolve_device(device)
    render = partial(render_any, device=device)

    cfg = QUICK if quick else FULL
    about = "scan files' CT rows" if scans else "head phantom ct-bone, anterior"
    table = Table(f"volumen bench lighting ({described}; {about}; spot lights)", [
        ("sweep", "sweep", "s"), ("volume", "volume", "s"), ("viewport", "viewport", "s"),
        ("distance", "eye distance (diag)", "s"), ("lights", "lights", "d"), ("shading", "shading", "s"),
        ("ms", "ms/frame", ".1f"), ("fps", "fps", ".2f"), ("x_phong", "x Phong", ".2f"),
        ("build_s", "light volume build s", ".3f"), ("seed_fps", "seeds' fps (GPU)", "s"),
        ("seed_phong_fps", "seeds' fps no shadows", "s"), ("bar_fps", "asked fps (issue 27)", "s"),
    ])
    table.notes.append(f"median of {repeat} frames after a warm-up frame; illumination volumes built in the "
                       "warm-up, their build time (all lights) given separately; 1 sample per voxel")
    table.notes.append("seeds: shadow rays in a GPU ray caster, 512x512x256 at 782x415: 0.09 fps (1 light), "
                       "0.04 fps (2 lights) vs 65 fps without shadows; scattering 35 fps (3 lights, 128 steps, "
                       "32 shadow steps, RTX 2080 Ti)")
    if scans:
        real_ct_rows(table, render, quick=quick, repeat=repeat, progress=progress, scans=scans)
        return table
    tf = TransferFunction.preset("ct-bone")
    volumes: dict = {}
    # compile every kernel first (on a tiny volume), so no timing below includes Numba's compilation
    tiny = phantom("head", size=(12, 16, 16))
    for sh in (Shading(mode="phong"), Shading(mode="shadows"), Shading(mode="shadows", shadow_method="direct"),
               Shading(mode="scattering"), Shading(mode="scattering", shadow_method="direct")):
        render(Scene(volume=tiny, transfer=tf, lights=_lights(tiny, 1), shading=sh), _camera(tiny), (8, 8))

    def volume(name, shape):
        if name not in volumes:
            t0 = time.perf_counter()
            volumes[name] = phantom("head", size=shape)
            progress(f"[{name}] head phantom in {time.perf_counter() - t0:.1f} s")
        return volumes[name]

    def frame(scene, cam, size):
        image = render(scene, cam, size)  # warm-up: JIT, caches, light volumes
        build = image.stats["timings"].get("light_volumes")
        ms = median_time(lambda: render(scene, cam, size), repeat=repeat, warmup=0) * 1e3
        return ms, build

    def cases(sweep, vname, vol, size, iname, dist, direct_ok):
        cam = _camera(vol, dist)
        for nl in (1, 2):
            base = Scene(volume=vol, volume_ref="phantom:head", transfer=tf, lights=_lights(vol, nl))
            ms_phong, _ = frame(base.with_(shading=Shading(mode="phong")), cam, size)
            seeds = vname == "512x512x256" and iname == "782x415" and dist is None
            row = dict(sweep=sweep, volume=vname, viewport=iname, distance="-" if dist is None else f"{dist:g}",
                       lights=nl)
            table.add(**row, shading="phong", ms=ms_phong, fps=1e3 / ms_phong, x_phong=1.0,
                      seed_fps=f"{SEEDS['phong']:g}" if seeds else None)
            methods = ["fast"] + (["direct"] if direct_ok else [])
            for m in methods:
                ms, build = frame(base.with_(shading=Shading(mode="shadows", shadow_method=m)), cam, size)
                table.add(**row, shading=f"shadows-{m}", ms=ms, fps=1e3 / ms, x_phong=ms / ms_phong,
                          build_s=build, seed_fps=f"{SEEDS[f'shadows_{nl}']:g}" if seeds else None,
                          seed_phong_fps=f"{SEEDS['phong']:g}" if seeds else None)
                progress(f"  {sweep} {vname} {iname} d={dist} {nl} light(s) shadows-{m}: {ms:.1f} ms "
                         f"(phong {ms_phong:.1f} ms)")

    size0 = next(iter(cfg["viewports"].items()))
    for vname, shape in cfg["volumes"].items():
        vol = volume(vname, shape)
        cases("volume", vname, vol, size0[1], size0[0], None, np.prod(shape) <= cfg["direct_max_voxels"])
        # the build time of one illumination volume, from scratch
        scene = Scene(volume=vol, transfer=tf, lights=_lights(vol, 1), shading=Shading(mode="shadows"))
        from volumen.render.raycast._cache import prepare

        prep = prepare(vol)
        prep.light_set = None
        if getattr(prep, "device", None) is not None:  # the cuda backend's illumination volumes
            prep.device.light_set = None
        image = render(scene, _camera(vol), (8, 8))
        table.add(sweep="build", volume=vname, lights=1, shading="light volume",
                  build_s=image.stats["timings"].get("light_volumes"))
    sname, sshape = cfg["sweep_volume"]
    svol = volume(sname, sshape)
    for iname, size in cfg["viewports"].items():
        cases("viewport", sname, svol, size, iname, None, size[0] * size[1] <= 376 * 200)
    for dist in cfg["distances"]:
        cases("distance", sname, svol, size0[1], size0[0], dist, False)

    # scattering: 3 lights, ~128 steps along the longest axis, direct light paths with ~32 steps
    cname, cshape = cfg["scatter_volume"]
    cvol = volume(cname, cshape)
    longest = max(cshape)
    spv = 128.0 / longest
    from volumen.core import Sampling

    base = Scene(volume=cvol, transfer=tf, lights=_lights(cvol, 3), sampling=Sampling(samples_per_voxel=spv))
    cam = _camera(cvol)
    size = size0[1]
    ms_phong, _ = frame(base.with_(shading=Shading(mode="phong")), cam, size)
    row = dict(sweep="scattering", volume=cname, viewport=size0[0], distance="-", lights=3)
    table.add(**row, shading="phong (128 steps)", ms=ms_phong, fps=1e3 / ms_phong, x_phong=1.0)
    for m, kw in (("fast", {}), ("direct", {"shadow_step": longest / 32.0})):
        ms, build = frame(base.with_(shading=Shading(mode="scattering", shadow_method=m, phase_g=0.3, **kw)), cam,
                          size)
        table.add(**row, shading=f"scattering-{m} (128 steps)", ms=ms, fps=1e3 / ms, x_phong=ms / ms_phong,
                  build_s=build, seed_fps=f"{SEEDS['scattering_3']:g}")
        progress(f"  scattering-{m}: {ms:.1f} ms (phong {ms_phong:.1f} ms)")
    real_ct_rows(table, render, quick=quick, repeat=repeat, progress=progress)
    return table


def filling_zoom(volume, camera, size) -> float:
    """The ``Camera.orbit`` zoom at which ``volume``'s voxel box, seen from ``camera`` (made by ``orbit`` at zoom
    1, which fits the bounding sphere in the vertical field of view), fills a ``size`` (w, h) picture: its
    extent along the camera's right and up axes meets the picture's width or height, whichever first -- but a
    perspective eye stays outside the box (5 % beyond its depth from the target), so a deep slab is seen from
    outside, not from within its tissue."""
    r, u, f = camera.basis()
    rel = volume.corners() - np.asarray(camera.target)
    half_w, half_h, half_d = (np.abs(rel @ axis).max() for axis in (r, u, f))
    radius = camera.parallel_scale  # orbit's sphere radius at zoom 1 (both projections); zoom divides it
    zoom = min(radius / half_h, radius * size[0] / size[1] / half_w)
    if camera.projection == "perspective":  # and the eye's distance
        zoom = min(zoom, camera.distance / (1.05 * half_d))
    return float(zoom)


def real_ct_rows(table, render, *, quick: bool = False, repeat: int = 3, progress=print, scans=()) -> None:
    """Add the CT rows (:data:`REAL_CT`: the real aorta and the whole-abdomen CT, at full rate and with adaptive
    sampling) to ``table``; a note instead where the aorta is missing. With ``scans`` (``_datasets.read_scan``),
    the rows of those scans instead, resampled to the same size (``_datasets.scan_at``), named by their number."""
    from ._datasets import load_dataset, scan_at

    shape = REAL_CT["quick_size" if quick else "size"]
    size = REAL_CT["quick_viewport" if quick else "viewport"]
    for scan in scans:
        if scan[1] is None:
            table.notes.append(f"{scan[0].name}: not a CT in Hounsfield units: no CT rows (the bars are for CTs)")
            continue
        _ct_rows(table, render, scan[0].name, scan_at(scan, shape), size, repeat, progress)
    for kind in () if scans else REAL_CT["kinds"]:
        loaded = load_dataset(kind, shape)
        if loaded is None:
            table.notes.append(f"{kind}: the VMTK aorta was not found (VOLUMEN_SHARED_DATA): no rows")
            continue
        _ct_rows(table, render, kind, loaded, size, repeat, progress)


def _ct_rows(table, render, kind, loaded, size, repeat, progress) -> None:
    """The rows of one CT: both presets, both views, the three models, full rate and adaptive."""
    from volumen.core import Camera

    from ._datasets import ray_shares

    vol, offset = loaded
    for view, zoom in (("default view", 1.0), ("filled", filling_zoom(vol, Camera.orbit(vol), size))):
        cams = [Camera.orbit(vol, azimuth=3.0 * i, zoom=zoom) for i in range(repeat + 1)]
        body = ray_shares(vol, offset, cams[0], size).get("body", float("nan"))
        for preset in REAL_CT["presets"]:
            _preset_rows(table, render, kind, preset, loaded, cams,
                         f"CT, {view}", f"zoom {zoom:.2f}, body on {body:.0%} of rays", size, repeat, progress)
            if zoom == 1.0:
                _moved_light_row(table, render, kind, preset, loaded, cams[0], size, repeat, progress)


def _preset_rows(table, render, kind, preset, loaded, cams, view, about, size, repeat, progress) -> None:
    """The rows of one CT in one preset from one view: the three models, full rate
    and adaptive, a new camera of ``cams`` each frame (the first one warms up)."""
    from dataclasses import replace

    from volumen.core import Scene, Shading, TransferFunction

    vol, offset = loaded
    name, iname = f"{kind} " + "x".join(str(n) for n in vol.shape[::-1]) + f" {preset}", f"{size[0]}x{size[1]}"
    base = Scene(volume=vol, transfer=TransferFunction.preset(preset).shifted(offset))
    cases = (("phong", 1, Shading(mode="phong")), ("shadows", 1, Shading(mode="shadows")),
             ("scattering", 3, Shading(mode="scattering", phase_g=0.3)))
    for (shading, n, sh), adaptive in ((c, a) for c in cases for a in (False, True)):
        scene = base.with_(lights=_lights(vol, n), shading=sh)
        scene = scene.with_(sampling=replace(scene.sampling, adaptive=adaptive))
        for _ in range(WARMUP_FRAMES):  # and the light volumes
            step = render(scene, cams[0], size).stats.get("step_mm", float("nan"))
        frames = iter(cams[1:])  # a new view each frame: nothing of the last frame is reused
        ms = median_time(lambda s=scene, f=frames: render(s, next(f), size), repeat=repeat, warmup=0) * 1e3
        bar, label = REAL_CT["bars"][shading], shading + (" adaptive" if adaptive else "")
        table.add(sweep=f"{view} ({about}, step {step:.2f} mm)", volume=name, viewport=iname, distance="-", lights=n,
                  shading=label, ms=ms, fps=1e3 / ms, bar_fps=f">= {bar:g}" + ("" if 1e3 / ms >= bar else " (not met)"))
        progress(f"  {name} {view}: {label} {n} light(s): {ms:.1f} ms ({1e3 / ms:.1f} fps; bar {bar:g})")


def _moved_light_row(table, render, kind, preset, loaded, camera, size, repeat, progress) -> None:
    """Shadows with one light that moves every frame (a user dragging it; the seeds' lights were moved by hand):
    each frame sweeps the light's illumination volume again, whose time the row gives beside the frame's."""
    from dataclasses import replace

    from volumen.core import Scene, Shading, TransferFunction

    vol, offset = loaded
    scene = Scene(volume=vol, transfer=TransferFunction.preset(preset).shifted(offset), shading=Shading(mode="shadows"))
    scene = scene.with_(sampling=replace(scene.sampling, adaptive=True))
    for _ in range(WARMUP_FRAMES):  # the kernels and the cells, with the light where the frames start
        render(scene.with_(lights=_lights(vol, 1)), camera, size)
    frames, builds = [], []
    for i in range(1, repeat + 1):  # 3 degrees further each frame, about the volume's centre
        t = time.perf_counter()
        image = render(scene.with_(lights=_lights(vol, 1, azimuth=3.0 * i)), camera, size)
        frames.append(time.perf_counter() - t)
        builds.append(image.stats["timings"].get("light_volumes", float("nan")))
    ms = float(np.median(frames)) * 1e3
    name = f"{kind} " + "x".join(str(n) for n in vol.shape[::-1]) + f" {preset}"
    table.add(sweep="CT, default view, the light moved every frame", volume=name, viewport=f"{size[0]}x{size[1]}",
              distance="-", lights=1, shading="shadows adaptive", ms=ms, fps=1e3 / ms,
              build_s=float(np.median(builds)))
    progress(f"  {name}: shadows adaptive, the light moved every frame: {ms:.1f} ms "
             f"(its illumination volume {np.median(builds) * 1e3:.0f} ms)")
