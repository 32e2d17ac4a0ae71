"""``volumen bench scale``: out-of-core (bricked, from OME-Zarr) vs in-memory ray casting of the same volume,
and batch throughput (studies a minute) on a Dask LocalCluster.

Warm frames: the abdomen CT phantom written as OME-Zarr, loaded once and drawn
while the camera orbits with a cache its bricks fit, each frame timed after the
in-memory render of the same camera (alternating): what an interactive view
does; the first frame reads the chunks and prepares the bricks, the warm ones
find them in the cache. Then the volume opened each frame (cold, a cache
smaller than the volume): a synthetic noisy blob (int16) written to a temporary
OME-Zarr; both renders use the same scene (default sampling: jitter, early termination
at 0.99), so the pictures agree within 1e-5: the table prints the largest
difference. Peak memory of the out-of-core render is the peak RSS of a fresh
process (:mod:`._scale_memory`), set beside its baseline (the same process
before the render), the cache bound and the volume's size.
"""

from __future__ import annotations

import csv
import tempfile
import time
from pathlib import Path

import numpy as np

from ._table import Table, median_time

__all__ = ["bench_scale", "bench_scale_huge"]

FULL = dict(edge=256, chunk=64, memory=8 << 20, size=(384, 384), studies=40, study_edge=64)
QUICK = dict(edge=64, chunk=16, memory=64 << 10, size=(64, 64), studies=6, study_edge=32)
#: warm frames: the abdomen CT phantom (nz, ny, nx; None: its own 224 x 202 x 244) at twice its size, a cache its
#: bricks fit
WARM = dict(shape=(448, 404, 488), chunk=64, memory=1 << 30, size=(512, 512), frames=4)
WARM_QUICK = dict(shape=(28, 25, 30), chunk=8, memory=4 << 20, size=(64, 64), frames=2)


def _blob(n: int) -> np.ndarray:
    z, y, x = np.indices((n, n, n), dtype=np.float32)
    c = n / 2
    d = 1000 * np.exp(-((x - c) ** 2 + (y - 0.8 * c) ** 2 + (z - 1.1 * c) ** 2) / (0.08 * n * n))
    return (d + np.random.default_rng(0).normal(0, 20, d.shape)).astype(np.int16)


def _scene(v, mode):
    from ..core import Sampling, Scene, TransferFunction

    tf = TransferFunction.window_level(600, 500, opacity=(0.0, 0.5))
    return Scene(volume=v, transfer=tf, mode=mode, sampling=Sampling())


def _render_rows(table, tmp: Path, edge, chunk, memory, size, repeat):
    from ..core import Camera, Volume
    from ..io import save
    from ..render import render
    from ..scale import render_bricked
    from ._scale_memory import out_of_core_peak

    v = Volume(_blob(edge))
    path = tmp / "blob.ome.zarr"
    save(v, path, chunks=chunk)
    cam = Camera.orbit(v, azimuth=30, elevation=20)
    for mode in ("composite", "mip"):
        scene = _scene(v, mode)
        ref, out = render(scene, cam, size), render_bricked(path, scene, cam, size, memory=memory)  # warm-ups
        t_mem = median_time(lambda s=scene: render(s, cam, size), repeat, warmup=0)
        t_ooc = median_time(lambda s=scene: render_bricked(path, s, cam, size, memory=memory), repeat, warmup=0)
        peak = out_of_core_peak(path, scene.with_(volume=None), cam, size, memory)
        diff = float(np.abs(out.rgba - ref.rgba).max())
        table.add(case=f"{mode} {edge}^3 int16 -> {size[0]}x{size[1]}, opened each frame", in_memory_s=t_mem,
                  out_of_core_s=t_ooc,
                  ratio=t_ooc / t_mem, bricks=f"{out.stats['bricks_drawn']}/{out.stats['bricks']}",
                  peak_mib=peak["peak"] / 2**20, growth_mib=(peak["peak"] - peak["baseline"]) / 2**20,
                  cache_mib=memory / 2**20, volume_mib=v.data.nbytes / 2**20, max_diff=diff)


def _timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return out, time.perf_counter() - t0


def _warm_row(table, tmp: Path, shape, chunk, memory, size, frames, peak=True):
    """ct-bone headlight on the abdomen phantom as OME-Zarr, loaded once and drawn while the camera orbits
    (the first frame reads the chunks and prepares the bricks; the warm ones find them in the cache),
    alternating with the in-memory render of the same frame; with ``peak``, the peak RSS of a fresh process
    drawing it warm."""
    from ..core import Camera, Scene, TransferFunction
    from ..data import phantom
    from ..io import load, save
    from ..render import render
    from ._scale_memory import memory_bound, out_of_core_peak

    v = phantom("abdomen", size=shape)
    path = tmp / "abdomen.ome.zarr"
    save(v, path, chunks=chunk)
    scene = Scene(volume=v, transfer=TransferFunction.preset("ct-bone"), mode="composite")
    chunked = scene.with_(volume=load(path))
    cams = [Camera.orbit(v, azimuth=30 + 10 * k, elevation=20) for k in range(frames + 1)]
    render(scene, cams[0], size)
    first, t_cold = _timed(lambda: render(chunked, cams[0], size, memory=memory))
    t_mem, t_ooc = [], []
    for cam in cams[1:]:
        ref, t = _timed(lambda c=cam: render(scene, c, size))
        t_mem.append(t)
        out, t = _timed(lambda c=cam: render(chunked, c, size, memory=memory))
        t_ooc.append(t)
    mem = {}
    if peak:
        r = out_of_core_peak(path, scene.with_(volume=None), cams[0], size, memory, frames=2)
        bound = memory_bound(r["baseline"], memory, size, (out.stats["brick"] + 3) ** 3, chunk ** 3 * 2)
        mem = dict(peak_mib=r["peak"] / 2**20, growth_mib=(r["peak"] - r["baseline"]) / 2**20, bound_mib=bound / 2**20)
    nz, ny, nx = v.shape
    tm, to = float(np.median(t_mem)), float(np.median(t_ooc))
    table.add(case=f"warm: ct-bone headlight {nx}x{ny}x{nz} int16 -> {size[0]}x{size[1]}, orbiting",
              in_memory_s=tm, out_of_core_s=to, ratio=to / tm,
              bricks=f"{out.stats['bricks_drawn']}/{out.stats['bricks']}", **mem, cache_mib=memory / 2**20,
              volume_mib=v.data.nbytes / 2**20, max_diff=float(np.abs(out.rgba - ref.rgba).max()))
    fs, ls = first.stats, out.stats
    table.notes.append(f"warm: the chunked volume loaded once; first frame {t_cold:.2f} s ({fs['chunk_reads']} chunk "
                       f"reads, {fs['normals_encoded']} bricks' normals encoded), then {frames} frames orbiting, each "
                       f"after the in-memory render of the same camera (medians); the last read {ls['chunk_reads']} "
                       f"chunks and encoded {ls['normals_encoded']} bricks' normals, "
                       f"{ls['cache_bytes'] / 2**20:.1f} MiB held in the cache"
                       + (". bound: baseline + cache + picture buffers + one brick + margin "
                          "(volumen/bench/_scale_memory.py), the child drawing twice" if peak else ""))


def _batch_row(table, tmp: Path, studies, edge, workers):
    from ..core import Volume
    from ..io import save
    from ..scale import run_batch

    z, y, x = np.indices((edge, edge, edge))
    man = tmp / "manifest.csv"
    with open(man, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["id", "path", "settings", "outputs"])
        for n in range(studies):
            d = np.where((x - edge / 2) ** 2 + (y - edge / 2) ** 2 + (z - edge / 2) ** 2 < (edge / 4 + n % 7) ** 2,
                         1000, -1000).astype(np.int16)
            p = tmp / f"s{n}.nii.gz"
            save(Volume(d, modality="CT", units="HU"), p)
            w.writerow([f"s{n}", str(p), '{"size": [256, 256], "views": [[0, 0], [90, 0]]}', "png;slices"])
    t0 = time.perf_counter()
    rows = run_batch(man, tmp / "results", workers=workers, progress=False)
    dt = time.perf_counter() - t0
    ok = sum(r["status"] == "ok" for r in rows)
    table.add(case=f"batch {studies} studies {edge}^3, 2 views 256^2 + a slice, {workers} workers",
              out_of_core_s=dt, studies_per_min=60.0 * ok / dt)


def bench_scale(*, quick: bool = False, repeat: int = 3, workers: int = 2) -> Table:
    """The table (see the module docstring); ``quick``: tiny sizes."""
    cfg = QUICK if quick else FULL
    table = Table("Out-of-core and distributed rendering", [
        ("case", "case", "s"), ("in_memory_s", "in memory s", ".3f"), ("out_of_core_s", "out of core / batch s", ".3f"),
        ("ratio", "ratio", ".2f"), ("bricks", "bricks drawn", "s"), ("peak_mib", "peak RSS MiB", ".1f"),
        ("growth_mib", "RSS growth MiB", ".1f"), ("bound_mib", "bound MiB", ".1f"),
        ("cache_mib", "cache MiB", ".1f"), ("volume_mib", "volume MiB", ".1f"), ("max_diff", "max |diff|", ".1e"),
        ("studies_per_min", "studies/min", ".1f")])
    with tempfile.TemporaryDirectory(prefix="volumen-bench-scale-") as d:
        tmp = Path(d)
        _warm_row(table, tmp, **(WARM_QUICK if quick else WARM), peak=not quick)  # quick: no third child
        _render_rows(table, tmp, cfg["edge"], cfg["chunk"], cfg["memory"], cfg["size"], repeat)
        _batch_row(table, tmp, cfg["studies"], cfg["study_edge"], workers)
    table.notes.append("ratio: out-of-core time / in-memory time, the same scene (default sampling, early "
                       "termination on); the out-of-core render reads its bricks from the OME-Zarr through the cache")
    table.notes.append("peak RSS: VmHWM of a fresh process drawing once out of core; growth: over its VmHWM after "
                       "a warm-up render of a tiny OME-Zarr (imports, compiled kernels)")
    table.notes.append("batch: the wall time includes starting the LocalCluster and its workers")
    return table


HUGE = dict(shape=(1024, 2048, 2048), chunk=64, brick=128, memory=1 << 30, size=(512, 512))


def bench_scale_huge(*, folder=None, **cfg) -> Table:
    """``volumen bench scale --huge``: the 2048 x 2048 x 1024 int16 synthetic volume (8 GiB, written plane by
    plane as OME-Zarr in a temporary folder under ``folder``, deleted afterwards) drawn out of core in a fresh
    process; its peak RSS against the bound of :func:`._scale_memory.memory_bound`."""
    import shutil

    from ..core import Camera, Scene, TransferFunction
    from ..scale import write_synthetic
    from ._scale_memory import memory_bound, out_of_core_peak

    c = {**HUGE, **cfg}
    table = Table("Out-of-core rendering of a volume larger than the cache", [
        ("case", "case", "s"), ("write_s", "write s", ".0f"), ("render_s", "render s", ".1f"),
        ("bricks", "bricks drawn", "s"), ("chunk_reads", "chunk reads", "d"), ("cache_mib", "cache MiB", ".0f"),
        ("baseline_mib", "baseline MiB", ".0f"), ("peak_mib", "peak RSS MiB", ".0f"), ("bound_mib", "bound MiB", ".0f"),
        ("volume_mib", "volume MiB", ".0f")])
    tmp = Path(tempfile.mkdtemp(prefix="volumen-huge-", dir=folder))
    try:
        t0 = time.perf_counter()
        v = write_synthetic(tmp / "huge.ome.zarr", c["shape"], chunks=c["chunk"])
        t_write = time.perf_counter() - t0
        scene = Scene(transfer=TransferFunction.window_level(600, 500, opacity=(0.0, 0.6)), mode="composite")
        r = out_of_core_peak(tmp / "huge.ome.zarr", scene, Camera.orbit(v, azimuth=30, elevation=20), c["size"],
                             c["memory"], brick=c["brick"])
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    bound = memory_bound(r["baseline"], c["memory"], c["size"], (c["brick"] + 3) ** 3, c["chunk"] ** 3 * 2)
    nz, ny, nx = c["shape"]
    table.add(case=f"composite headlight {nx}x{ny}x{nz} int16 -> {c['size'][0]}x{c['size'][1]}, bricks {c['brick']}",
              write_s=t_write, render_s=r["seconds"], bricks=f"{r['bricks_drawn']}/{r['bricks']}",
              chunk_reads=r["chunk_reads"], cache_mib=c["memory"] / 2**20, baseline_mib=r["baseline"] / 2**20,
              peak_mib=r["peak"] / 2**20, bound_mib=bound / 2**20, volume_mib=v.data.nbytes / 2**20)
    table.notes.append("peak RSS: VmHWM of the child process; baseline: its VmHWM after importing volumen and "
                       "drawing a tiny OME-Zarr out of core (compiled kernels, Zarr); bound: baseline + cache + "
                       "picture buffers + one brick's working set + a fixed margin (volumen/bench/_scale_memory.py)")
    table.notes.append("the volume is written plane by plane and deleted afterwards")
    return table
