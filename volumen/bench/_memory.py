"""``volumen bench memory``: the peak memory a picture takes beside its volume, per lighting model.

Each row is one fresh process (``bench._render.peak_memory``): it compiles on a tiny volume, notes its peak RSS
(the baseline: imports and kernels), loads an int16 CT (the torso phantom at :data:`SHAPE`, 700 x 512 x 512 =
350 MiB; :data:`QUICK_SHAPE` with ``--quick``), draws one composite ``ct-bone`` picture of :data:`SIZE` with
the shading model and notes its peak RSS again. The table gives the peak over the baseline as a multiple of
the volume's bytes, the volume itself included (what a command that loads a scan and draws it needs beyond the
program), and what the picture added on top of the volume: the per-voxel tables of the model (normal codes,
illumination volumes, block grids) and the picture's buffers.
"""

from __future__ import annotations

from collections.abc import Callable

from ._render import peak_memory
from ._table import Table, machine_info

__all__ = ["bench_memory", "SHAPE", "QUICK_SHAPE", "SIZE", "SHADINGS"]

#: (nx, ny, nz) voxels of the CT: 700 slices of 512 x 512 (350 MiB of int16)
SHAPE = (512, 512, 700)
QUICK_SHAPE = (64, 64, 48)
#: the picture (pixels)
SIZE = (512, 512)
SHADINGS = ("none", "headlight", "phong", "shadows", "scattering")


def bench_memory(*, quick: bool = False, shadings=SHADINGS,
                 progress: Callable[[str], None] = print) -> Table:
    """The table of peak memory per shading model (see the module docstring)."""
    shape = QUICK_SHAPE if quick else SHAPE
    size = (64, 64) if quick else SIZE
    table = Table(f"Peak memory of one {size[0]}x{size[1]} picture of a {shape[0]}x{shape[1]}x{shape[2]} int16 CT "
                  "(composite ct-bone, CPU, a fresh process per row)",
                  [("shading", "shading", ""), ("volume_mib", "volume MiB", ".0f"),
                   ("baseline_mib", "baseline MiB", ".0f"), ("peak_mib", "peak MiB", ".0f"),
                   ("with_volume", "x volume, with it", ".2f"), ("added", "x volume, added", ".2f")])
    for shading in shadings:
        m = peak_memory("torso", shape, shading, size)
        v, base, peak = m["volume_bytes"], m["baseline_bytes"], m["peak_bytes"]
        table.add(shading=shading, volume_mib=v / 2**20, baseline_mib=base / 2**20, peak_mib=peak / 2**20,
                  with_volume=(peak - base) / v, added=(peak - base) / v - 1.0)
        progress(f"  {shading}: {(peak - base) / v:.2f}x the volume over the baseline")
    table.notes.append("x volume, with it: (peak - baseline) / the volume's bytes, the loaded volume included; "
                       "added: that less the volume itself")
    table.notes.append(f"machine: {machine_info()}")
    return table
