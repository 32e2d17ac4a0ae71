"""Peak memory of an out-of-core render, read as the peak RSS (``VmHWM``) of a fresh child process.

:func:`out_of_core_peak` starts ``python -c`` running :func:`_child`, which
imports volumen, draws a tiny OME-Zarr out of core (``volumen.render.render``
on the chunked volume ``volumen.load`` gives) with the same scene (the kernels
compile, Zarr and its codecs load), notes its peak RSS so far -- the
*baseline*, measured, not assumed -- then draws the big one and notes its peak
RSS again. :func:`memory_bound` states what the big render may add on top of
the baseline: the chunk cache, the picture buffers, one brick's working set,
and a fixed margin. ``volumen bench scale --huge`` runs it on a 2048 x 2048 x
1024 int16 volume (8 GiB); ``tests/scale/test_memory.py`` on 512 x 512 x 256.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from pathlib import Path

__all__ = ["out_of_core_peak", "memory_bound", "MARGIN", "FRAME_BYTES_PER_PIXEL"]

#: picture buffers of a bricked render, bytes a pixel: the running partial (rgba, depth, value: 24), the
#: brick's outputs (rgba, depth, value, samples: 28), the carried opacity (4), and the compositing temporaries
#: and conversions (about as much again): 128 bytes, rounded up
FRAME_BYTES_PER_PIXEL = 128
#: fixed margin for what the baseline does not show: the allocator's free lists and arenas, Zarr's decoding
#: buffers and thread pools warming up on bigger chunks, Python objects of the bricks' plan
MARGIN = 48 << 20


def memory_bound(baseline: int, cache: int, size, brick_voxels: int, chunk_bytes: int, itemsize: int = 2) -> int:
    """Peak RSS allowed (bytes): ``baseline + cache + picture buffers + one brick's working set + MARGIN``.

    The brick's working set: its voxels three times (the box assembled from the chunks, the view picked from
    it, the contiguous copy the ray caster reads) and four chunks' worth of decoding buffers.
    """
    frame = FRAME_BYTES_PER_PIXEL * int(size[0]) * int(size[1])
    brick = 3 * brick_voxels * itemsize + 4 * chunk_bytes
    return int(baseline + cache + frame + brick + MARGIN)


def _hwm() -> int:
    """Peak resident set of this process, bytes (``VmHWM``)."""
    for line in open("/proc/self/status"):
        if line.startswith("VmHWM"):
            return int(line.split()[1]) * 1024
    raise RuntimeError("no VmHWM in /proc/self/status (Linux only)")


def _child(spec_path: str) -> None:
    """Run in the child: warm up on the tiny store, then draw the big one; prints one ``MEM {json}`` line."""
    import time

    from volumen.core import Camera, Scene
    from volumen.io import load
    from volumen.render import render

    spec = json.loads(Path(spec_path).read_text())
    scene = Scene.from_dict(spec["scene"])

    def draw(path, camera, size, **how):  # volumen.render on the chunked volume: out of core
        return render(scene.with_(volume=load(path)), Camera.from_dict(camera), size, memory=spec["memory"],
                      **how)

    draw(spec["tiny"], spec["tiny_camera"], (8, 8))
    base = _hwm()
    t0 = time.perf_counter()
    out = draw(spec["path"], spec["camera"], tuple(spec["size"]), brick=spec["brick"])
    dt = time.perf_counter() - t0
    peak = _hwm()
    st = out.stats
    keys = ("chunk_reads", "bricks", "bricks_drawn", "cache_peak_bytes")
    print("MEM " + json.dumps({"baseline": base, "peak": peak, "seconds": dt, **{k: st[k] for k in keys},
                               "alpha_mean": float(out.rgba[..., 3].mean())}))


def out_of_core_peak(path, scene, camera, size, memory: int, *, brick: int | None = None,
                     timeout: float = 3600) -> dict:
    """Peak RSS of a fresh process drawing the OME-Zarr at ``path`` out of core (see the module docstring).

    Returns the child's numbers: ``baseline`` and ``peak`` (bytes), ``seconds`` of the big render,
    ``chunk_reads``, ``bricks``, ``bricks_drawn``, ``cache_peak_bytes``, ``alpha_mean``.
    """
    from ..core import Camera
    from ..scale import write_synthetic

    with tempfile.TemporaryDirectory(prefix="volumen-peak-") as tmp:
        tiny = write_synthetic(Path(tmp) / "tiny.ome.zarr", (16, 16, 16), chunks=8)
        spec = {"scene": scene.with_(volume=None).to_dict(), "camera": camera.to_dict(), "size": list(size),
                "memory": int(memory), "brick": brick, "path": str(path), "tiny": str(Path(tmp) / "tiny.ome.zarr"),
                "tiny_camera": Camera.orbit(tiny).to_dict()}
        (Path(tmp) / "spec.json").write_text(json.dumps(spec))
        code = "import sys; from volumen.bench._scale_memory import _child; _child(sys.argv[1])"
        r = subprocess.run([sys.executable, "-c", code, str(Path(tmp) / "spec.json")], capture_output=True,
                           text=True, timeout=timeout)
    line = [x for x in r.stdout.splitlines() if x.startswith("MEM ")]
    if r.returncode != 0 or not line:
        raise RuntimeError(f"out-of-core peak-memory run failed (exit {r.returncode}): {r.stderr[-2000:]}")
    return json.loads(line[0][4:])
