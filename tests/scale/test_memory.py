"""Peak memory of an out-of-core render: the peak RSS (VmHWM) of a fresh child process stays under the stated
cache plus a measured overhead, far below the volume's size."""

import sys

import pytest

from volumen.core import Camera, Scene, TransferFunction

pytest.importorskip("zarr", reason="the scale extra (zarr) is not installed")
if not sys.platform.startswith("linux"):
    pytest.skip("peak RSS is read from /proc/self/status (Linux only)", allow_module_level=True)

from volumen.bench._scale_memory import MARGIN, memory_bound, out_of_core_peak
from volumen.scale import write_synthetic

MiB = 1 << 20


def test_peak_rss_under_cache_plus_overhead(tmp_path):
    """512 x 512 x 256 int16 (128 MiB, written plane by plane) drawn lit (headlight) with a 16 MiB cache.

    Bound = baseline (the same child's peak RSS after importing volumen and drawing a tiny OME-Zarr out of
    core: interpreter, NumPy, Numba's compiled kernels, Zarr) + cache + 128 bytes a pixel of picture buffers
    + one brick's working set (3 x its 130^3 voxels + 4 chunks) + a 48 MiB margin. The render's own growth
    over the baseline must also stay under half the volume.
    """
    path = tmp_path / "big.ome.zarr"
    v = write_synthetic(path, (256, 512, 512), chunks=64)
    scene = Scene(transfer=TransferFunction.window_level(600, 500, opacity=(0.0, 0.6)), mode="composite")
    cache, size = 16 * MiB, (128, 128)
    r = out_of_core_peak(path, scene, Camera.orbit(v, azimuth=30, elevation=20), size, cache)
    bound = memory_bound(r["baseline"], cache, size, 130 ** 3, 64 ** 3 * 2)  # bricks of 128 (default) + pads
    print(f"peak RSS {r['peak'] / MiB:.1f} MiB, baseline {r['baseline'] / MiB:.1f} MiB, growth "
          f"{(r['peak'] - r['baseline']) / MiB:.1f} MiB, cache {cache / MiB:.0f} MiB (used "
          f"{r['cache_peak_bytes'] / MiB:.1f}), bound {bound / MiB:.1f} MiB (margin {MARGIN / MiB:.0f}), volume "
          f"{v.data.nbytes / MiB:.0f} MiB; {r['bricks_drawn']}/{r['bricks']} bricks, {r['chunk_reads']} chunk "
          f"reads, {r['seconds']:.1f} s")
    assert r["bricks_drawn"] > r["bricks"] // 2 and r["alpha_mean"] > 0.05  # most of the volume is drawn
    assert r["cache_peak_bytes"] <= cache
    assert r["peak"] <= bound
    assert r["peak"] - r["baseline"] < v.data.nbytes / 2
