"""Illumination volumes built on the device: the same lattices as the CPU, swept one thread per lattice ray.

The planning (:func:`volumen.render.raycast.plan_lattice`), the
cache keys and the layout (meta rows, one flat float32 buffer) are those of
the CPU; the sweep runs ``lattice_step`` (the shared per-ray step) in the
``sweep`` kernel, reading the normalized volume already on the device
through a permuted view. The set is kept on the volume's
:class:`~._memory.DeviceVolume`; a light whose key is unchanged keeps its
lattice (copied on the device), only new or changed ones are swept.
"""

from __future__ import annotations

import time

import numpy as np

from ..raycast import (
    DIRECT,
    LATTICE,
    LV_AXA,
    LV_AXB,
    LV_AXC,
    LV_KIND,
    LV_NK,
    LV_NU,
    LV_NV,
    LV_OFF,
    NMETA,
    Sweep,
    plan_lattice,
)
from ._memory import device_volume, permuted

__all__ = ["device_light_volumes"]


class _DeviceSet:
    def __init__(self, keys, lvm, lvd):
        self.keys, self.lvm, self.lvd = keys, lvm, lvd


def _size(m) -> int:
    return int(m[LV_NK] * m[LV_NV] * m[LV_NU])


def device_light_volumes(prep, keys, positions_index, box_lo, box_hi, med, geo, planes, nplanes, ds0, kext, scale,
                         method: str):
    """Like the CPU's illumination volumes (``raycast.pack_frame``'s default), with the buffer ``lvd`` on the device.

    Returns ``(lvm (n, NMETA) float64 host, lvd device float32, built)``.
    """
    from numba import cuda

    from . import _kernels

    dev = device_volume(prep)
    n = len(keys)
    if method == "direct" or n == 0:
        lvm = np.zeros((max(n, 1), NMETA))
        lvm[:n, LV_KIND] = DIRECT
        return lvm, dev.put("lvd_none", np.ones(1, np.float32)), 0
    old = dev.light_set
    if old is not None and old.keys == tuple(keys):
        return old.lvm, old.lvd, 0
    olds = {} if old is None else {k: old.lvm[i] for i, k in enumerate(old.keys)}
    metas = []
    off = 0
    for i in range(n):
        m = olds[keys[i]].copy() if keys[i] in olds else plan_lattice(positions_index[i], box_lo, box_hi,
                                                                       prep.u.shape, scale)
        if m is None or m[LV_KIND] != LATTICE:
            m = np.zeros(NMETA)
            m[LV_KIND] = DIRECT
        else:
            m[LV_OFF] = off
            off += _size(m)
        metas.append(m)
    lvd = cuda.to_device(np.ones(1, np.float32)) if off == 0 else cuda.device_array(off, np.float32)
    built = 0
    t = time.perf_counter()
    d_med = med._replace(vol=dev.put("vol", med.vol, same_object=True),
                         extinction=dev.put("extinction", med.extinction),
                         label_map=dev.put("label_map", med.label_map, same_object=True),
                         label_lut=dev.put("label_lut", med.label_lut),
                         lut=dev.put("lut", med.lut))
    d_aff = dev.put("aff", np.ascontiguousarray(np.asarray(prep.affine, float)[:3, :4]))
    d_geo = dev.put("geo", geo)
    d_planes = dev.put("planes", planes)
    for i, m in enumerate(metas):
        if m[LV_KIND] != LATTICE:
            continue
        o, size = int(m[LV_OFF]), _size(m)
        shape = tuple(int(m[j]) for j in (LV_NK, LV_NV, LV_NU))
        if keys[i] in olds:  # unchanged light: keep its lattice
            oo = int(olds[keys[i]][LV_OFF])
            lvd[o:o + size].copy_to_device(old.lvd[oo:oo + size])
            continue
        axes = tuple(int(m[j]) for j in (LV_AXA, LV_AXB, LV_AXC))
        blocks, threads = _kernels.grid_2d(shape[2], shape[1])
        sw = Sweep.of(d_med, lambda x, axes=axes: permuted(x, axes), d_aff, d_geo, d_planes, cuda.to_device(m),
                      nplanes, ds0, kext)
        _kernels.sweep[blocks, threads](sw, lvd[o:o + size].reshape(shape))
        built += 1
    if built:
        cuda.synchronize()
        prep.timings["light_volumes"] = time.perf_counter() - t
    lvm = np.stack(metas)
    dev.light_set = _DeviceSet(tuple(keys), lvm, lvd)
    return lvm, lvd, built
