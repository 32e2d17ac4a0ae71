"""``volumen bench render``: ray casting on real scans and whole-region CTs, against VTK in the same process.

Data sets (:mod:`._datasets`), each CT at two sizes, 244x202x224 and 366x303x336 int16: the VMTK aorta
CTA (a cropped angiogram, its scanner units converted to Hounsfield units: ``_datasets.AORTA_HU``), and the
whole-abdomen and whole-chest CTs built for the purpose (soft tissue in
most rays); the MRI template from ``volumen.data.sample`` where installed, as it is (301x370x316 uint8) and
at half its size. Per CT the notes give the share of the picture's rays that cross the body and soft
tissue (:func:`._datasets.ray_shares`).
Cases: composite ct-bone headlight, composite ct-skin-bone headlight (translucent), composite ct-bone
unshaded, at full rate (``Sampling(adaptive=False)``: sampling "full"), plus mip and isosurface; the three
composite cases again with the default sampling (``Sampling()``, adaptive for these models: sampling "default",
what ``render`` and the viewers draw with no flags), whose rows also give the mean |RGB diff| from the full-rate
picture.

Timing: VTK's ``vtkFixedPointVolumeRayCastMapper`` renders the same scene
(volume, camera, transfer-function points, sample distance, image size) with
the same number of threads as Numba, in alternating rounds (ours, VTK, ours,
VTK, ...), so both see the same machine load; the table gives each median,
the ratio of the medians ours / VTK and the spread of the rounds' own ratios
(lowest and highest), and the mean |RGB diff| of the two pictures; a summary
gives each case's ratio over the CTs (lowest, median, highest). The peak
memory of a shaded render is measured in a fresh subprocess (its peak RSS,
``VmHWM``, before loading the scan and after one shaded frame) and printed
against the volume's own bytes.
"""

from __future__ import annotations

import os
import resource
import subprocess
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from ..core import adaptive_on
from ._datasets import CT_KINDS, SOFT_TISSUE_HU, aorta_path, load_dataset, ray_shares
from ._table import WARMUP_FRAMES, Table, resolve_device
from ._vtk_peer import VtkScene, vtk_available

__all__ = ["bench_render", "CASES", "DATASETS", "IMAGES", "aorta_path", "load_dataset", "peak_memory"]

IMAGES = {"512x512": (512, 512)}
#: the bars on ours / VTK for every CT, by (shading, preset) of the composite cases
BARS = {("headlight", "ct-skin-bone"): 0.7, ("headlight", "ct-bone"): 0.5, ("none", "ct-bone"): 0.5}
#: (mode, shading, preset, sampling: "full" (no adaptive sampling) or "default" (``Sampling()``: adaptive here))
CASES = [
    ("composite", "headlight", "ct-bone", "full"),
    ("composite", "headlight", "ct-skin-bone", "full"),
    ("composite", "none", "ct-bone", "full"),
    ("mip", "none", None, "full"),
    ("isosurface", "headlight", None, "full"),
    ("composite", "headlight", "ct-bone", "default"),
    ("composite", "headlight", "ct-skin-bone", "default"),
    ("composite", "none", "ct-bone", "default"),
]
#: data set name -> (kind, (nx, ny, nz) or None); a scan of the user's: ("scan", size, scan) (``--scan``:
#: ``_datasets.scan_datasets``)
DATASETS = {f"{kind}-{s}": (kind, tuple(int(n) for n in s.split("x")))
            for kind in CT_KINDS for s in ("244x202x224", "366x303x336")}
#: the MRI template (301x370x316 uint8 at 0.5 mm) as installed and at half the size
DATASETS.update({"mri-template-151x185x158": ("mri", (151, 185, 158)), "mri-template-301x370x316": ("mri", None)})
#: measured for peak memory only (a large case: a 700x512x512 int16 CT, 0.37 GB, where the fixed baseline of
#: imports and compiled kernels does not dominate), besides the aorta sizes timed
MEMORY_DATASETS = {"aorta-512x512x700": ("aorta", (512, 512, 700))}
QUICK = {"datasets": {"aorta-96x80x88": ("aorta", (96, 80, 88)), "abdomen-61x51x56": ("abdomen", (61, 51, 56))},
         "images": {"128x128": (128, 128)}, "memory_datasets": {}}


def _scene(volume, mode, shading, preset, offset, spv, adaptive=False):
    """The benchmark's scene; ``adaptive`` None: the default sampling."""
    from volumen.core import Isosurface, Sampling, Scene, Shading, TransferFunction
    from volumen.render import default_transfer

    if preset and offset is not None:
        tf = TransferFunction.preset(preset).shifted(offset)
    else:
        tf = default_transfer(volume, "composite" if mode == "composite" else mode)
    iso = 300.0 + (offset or 0.0) if offset is not None else float(np.percentile(volume.data[::4, ::4, ::4], 90))
    return Scene(volume=volume, transfer=tf, mode=mode, shading=Shading(mode=shading),
                 sampling=Sampling(samples_per_voxel=spv, adaptive=adaptive), isosurface=Isosurface(value=iso))


def _alternate(ours, theirs, rounds: int) -> tuple[float, float]:
    """Median seconds of ``ours()`` and ``theirs()`` timed in alternating rounds."""
    a, b = _rounds(ours, theirs, rounds)
    return float(np.median(a)), (float(np.median(b)) if b else float("nan"))


def _rounds(ours, theirs, rounds: int) -> tuple[list, list]:
    """Seconds of ``ours()`` and ``theirs()`` (None: not timed) in ``rounds`` alternating rounds."""
    a, b = [], []
    for _ in range(rounds):
        t = time.perf_counter()
        ours()
        a.append(time.perf_counter() - t)
        if theirs is not None:
            t = time.perf_counter()
            theirs()
            b.append(time.perf_counter() - t)
    return a, b


def peak_memory(kind: str, shape, shading: str = "headlight", size=(512, 512)) -> dict:
    """Peak RSS of a fresh process rendering one ``shading`` frame (composite ct-bone) of a data set.

    The data set is made here and saved as ``.npy``; the fresh process imports
    volumen, compiles on a tiny volume, notes its RSS (the baseline), loads the
    array (exactly the volume's bytes), renders once and notes its peak RSS.
    Returns ``{"volume_bytes", "baseline_bytes", "peak_bytes"}``.
    """
    import json
    import tempfile

    vol, off = load_dataset(kind, shape)
    with tempfile.TemporaryDirectory() as tmp:
        np.save(Path(tmp) / "data.npy", vol.data)
        meta = {"spacing": list(vol.spacing), "affine": np.asarray(vol.affine).tolist(), "offset": off}
        (Path(tmp) / "meta.json").write_text(json.dumps(meta))
        del vol
        code = (
            "import json, resource, sys, numpy as np\n"
            "def hwm():  # peak RSS of this process image (ru_maxrss would keep the forking parent's peak)\n"
            "    try:\n"
            "        return [int(x.split()[1]) for x in open('/proc/self/status') if x.startswith('VmHWM')][0]\n"
            "    except (OSError, IndexError):\n"
            "        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss\n"
            "from volumen.bench._render import _scene\n"
            "from volumen.core import Camera, Volume\n"
            "from volumen.data import phantom\n"
            "from volumen.render import render\n"
            "tiny = phantom('head', size=(16, 16, 16))\n"
            "tiny = Volume(tiny.data.astype(np.int16), spacing=tiny.spacing, affine=tiny.affine, modality='CT')\n"
            f"render(_scene(tiny, 'composite', {shading!r}, 'ct-bone', 0.0, 1.0, None), Camera.orbit(tiny), (8, 8))\n"
            "base = hwm()\n"
            "m = json.loads(open(sys.argv[1] + '/meta.json').read())\n"
            "vol = Volume(np.load(sys.argv[1] + '/data.npy'), spacing=tuple(m['spacing']), "
            "affine=np.array(m['affine']), modality='CT')\n"
            f"render(_scene(vol, 'composite', {shading!r}, 'ct-bone', m['offset'], 1.0, None), Camera.orbit(vol), "
            f"{tuple(size)!r})\n"
            "peak = hwm()\n"
            "print('MEM', vol.data.nbytes, base * 1024, peak * 1024)\n"
        )
        r = subprocess.run([sys.executable, "-c", code, tmp], capture_output=True, text=True, timeout=900)
    line = [x for x in r.stdout.splitlines() if x.startswith("MEM")]
    if not line:
        raise RuntimeError(f"peak-memory run failed: {r.stderr[-2000:]}")
    nbytes, base, peak = (int(x) for x in line[0].split()[1:])
    return {"volume_bytes": nbytes, "baseline_bytes": base, "peak_bytes": peak}


def _case(table, scene, camera, size, backend, rounds, threads, use_vtk, label):
    from volumen.render import render

    for _ in range(WARMUP_FRAMES):
        image = render(scene, camera, size, device=backend)
    peer = None
    if use_vtk and scene.mode == "composite":
        try:
            peer = VtkScene(scene, camera, size, threads=threads)
        except ValueError as exc:  # e.g. a flipped or oblique grid, which the VTK peer does not translate
            table.notes.append(f"{label['data']}: no VTK peer ({exc})")
        else:
            theirs = peer.render()
    a, b = _rounds(lambda: render(scene, camera, size, device=backend),
                   None if peer is None else peer.render_only, rounds)
    ours_s = float(np.median(a))
    row = table.add(**label, ms=ours_s * 1e3, msamples_s=float(image.stats.get("samples", 0)) / ours_s * 1e-6)
    if peer is not None:
        each = np.divide(a, b)  # the rounds' own ratios: their spread is the noise of the machine
        row.update(vtk_ms=float(np.median(b)) * 1e3, ratio_vtk=ours_s / float(np.median(b)),
                   ratio_lo=float(each.min()), ratio_hi=float(each.max()),
                   diff_vtk=float(np.mean(np.abs(np.clip(image.rgba[..., :3], 0, 1) - theirs))))
    if adaptive_on(scene):
        full = render(replace(scene, sampling=replace(scene.sampling, adaptive=False)), camera, size, device=backend)
        shown, ref = (np.clip(im.rgba[..., :3], 0, 1) for im in (image, full))
        row["diff_full"] = float(np.mean(np.abs(shown - ref)))
    return row


def _summary(table) -> None:
    """Notes: each case's ratio to VTK over the CT data sets, scans of the user's among them (lowest, median,
    highest), and how many are within the bar (:data:`BARS`) as printed (two decimals)."""
    by_case: dict = {}
    for r in table.rows:
        if "ratio_vtk" in r and r.get("ct"):
            key = (r["image"], r["mode"], r["shading"], r["preset"], r["sampling"])
            by_case.setdefault(key, []).append((r["ratio_vtk"], r["data"]))
    for (image, mode, shading, preset, sampling), got in by_case.items():
        ratios = sorted(got)
        median = float(np.median([x for x, _ in ratios]))
        met, bar = "", BARS.get((shading, preset))
        if bar is not None:
            within = sum(round(x, 2) <= bar for x, _ in ratios)  # as printed
            met = f"; bar <= {bar:.2f} (issue 27): {within} of {len(ratios)} within"
        table.notes.append(f"{image} {mode} {shading} {preset} {sampling}: ours/VTK over {len(ratios)} CTs lowest "
                           f"{ratios[0][0]:.2f} ({ratios[0][1]}), median {median:.2f}, highest {ratios[-1][0]:.2f} "
                           f"({ratios[-1][1]}){met}")


def _memory_notes(table, datasets, progress) -> None:
    """Peak memory of a shaded (headlight) and an unshaded render of each aorta data set, as table notes."""
    for dname, (kind, shape, *_) in datasets.items():
        if kind != "aorta" or aorta_path() is None:
            continue
        for shading in ("headlight", "none"):
            m = peak_memory(kind, shape, shading)
            v, base, peak = m["volume_bytes"], m["baseline_bytes"], m["peak_bytes"]
            table.notes.append(
                f"peak memory of {'a shaded' if shading != 'none' else 'an unshaded'} render ({dname}, fresh process):"
                f" {peak / 2**20:.0f} MiB = {peak / v:.2f}x the volume's {v / 2**20:.0f} MiB; above the "
                f"{base / 2**20:.0f} MiB baseline (imports, compiled kernels): {(peak - base) / v:.2f}x")
            progress(table.notes[-1])


def bench_render(*, datasets=None, images=None, cases=None, spv: float = 1.0, rounds: int = 5, repeat=None,
                 with_vtk: bool = True, backend: str = "cpu", memory: bool = True, progress=print,
                 volumes=None, memory_datasets=None) -> Table:
    """Run the benchmark; returns the :class:`Table` (print ``table.render()``, save with ``table.save``).

    ``datasets``: name -> (kind, (nx, ny, nz)[, scan]) (default :data:`DATASETS`; scans of the user's:
    ``_datasets.scan_datasets``); ``rounds`` alternating timed
    rounds per case after a warm-up (``repeat``, the CLI's name, overrides it); ``memory``: also measure the
    peak memory of a shaded and an unshaded render of each aorta size (and of ``memory_datasets``, default
    :data:`MEMORY_DATASETS`) in a fresh process. ``volumes`` (older name): head
    phantom sizes (nz, ny, nx).
    """
    import numba

    from volumen.core import Camera

    if volumes:
        datasets = {f"head-phantom-{'x'.join(map(str, s[::-1]))}": ("head", s[::-1]) for s in volumes.values()}
    datasets = datasets or DATASETS
    rounds = int(repeat or rounds)
    images, cases = images or IMAGES, cases or CASES
    backend, device = resolve_device(backend)
    threads = numba.get_num_threads()
    use_vtk = with_vtk and vtk_available()
    table = Table(f"volumen bench render ({device} ray casting vs VTK fixed-point, {threads} threads each)", [
        ("data", "data", "s"), ("image", "image", "s"), ("mode", "mode", "s"), ("shading", "shading", "s"),
        ("preset", "preset", "s"), ("sampling", "sampling", "s"), ("ms", "ms/frame", ".1f"),
        ("msamples_s", "Msamples/s", ".0f"),
        ("vtk_ms", "VTK ms", ".1f"), ("ratio_vtk", "ours/VTK", ".2f"), ("ratio_lo", "rounds' lowest", ".2f"),
        ("ratio_hi", "highest", ".2f"), ("diff_vtk", "mean |diff| vs VTK", ".4f"),
        ("diff_full", "mean |diff| vs full rate", ".4f"),
    ])
    table.notes.append(f"samples per voxel {spv}; medians of {rounds} alternating rounds (ours, VTK) after a "
                       f"warm-up; load average at start {os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs")
    if not use_vtk:
        table.notes.append("VTK not installed (pip install 'volumen[bench]') or --no-vtk: no peer columns")
    for dname, (kind, shape, *scan) in datasets.items():
        loaded = load_dataset(kind, shape, *scan)
        if loaded is None:
            table.notes.append(f"{dname}: source missing, skipped")
            continue
        vol, offset = loaded
        progress(f"[{dname}] {vol.shape[::-1]} (x, y, z) {vol.data.dtype}, {vol.data.nbytes / 2**20:.0f} MiB")
        camera = Camera.orbit(vol, view="anterior")
        for iname, size in images.items():
            shares = ray_shares(vol, offset, camera, size)
            if shares:
                table.notes.append(f"{dname} at {iname}: {100 * shares['body']:.0f}% of the rays cross the body, "
                                   f"{100 * shares['soft']:.0f}% soft tissue ({SOFT_TISSUE_HU[0]:.0f}.."
                                   f"{SOFT_TISSUE_HU[1]:.0f} HU)")
                progress("  " + table.notes[-1])
            for mode, shading, preset, sampling in cases:
                adaptive = None if sampling == "default" else False
                scene = _scene(vol, mode, shading, preset, offset, spv, adaptive=adaptive)
                shown = (preset if offset is not None else "data default") if preset else "-"
                label = dict(data=dname, image=iname, mode=mode, shading=shading, preset=shown, sampling=sampling)
                row = _case(table, scene, camera, size, backend, rounds, threads, use_vtk, label)
                row.update(kind=kind, ct=kind in CT_KINDS or (kind == "scan" and offset is not None),
                           **{f"rays_{k}": v for k, v in shares.items()})
                progress(f"  {iname} {mode}/{shading}/{shown}/{sampling}: {row['ms']:.1f} ms"
                         + (f", VTK {row['vtk_ms']:.1f} ms, ratio {row['ratio_vtk']:.2f}" if "vtk_ms" in row else ""))
    _summary(table)
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    table.notes.append(f"this process's peak RSS: {rss:.0f} MiB")
    if memory:
        _memory_notes(table, {**datasets, **(MEMORY_DATASETS if memory_datasets is None else memory_datasets)},
                      progress)
    return table
