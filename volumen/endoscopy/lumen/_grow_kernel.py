"""Compiled priority flood for :mod:`._grow` (arrays and scalars only): the lumen's volume against its threshold.

The data is read as ``u = sign * value`` (``sign`` +1 for an air lumen, -1 for a
contrast lumen), so the lumen is where ``u`` is low and the wall where it is high.
From the seed, voxels are flooded in order of their *flood level*: the highest ``u``
met on the way from the seed (the level a threshold must reach for region growing to
get there), never past ``u_max``. The volume grown at a threshold ``c`` is the number of
voxels whose flood level is at most ``c``. Checks begin once the flood holds 95 % of the
``targets`` (voxels known to be lumen: the lumen round the seed, whose values vary more
than its noise where the contrast mixes unevenly; a few may lie past a bit of partial
volume) and the level has reached ``u0``; they are made at that level and every ``step``
above it. A
step is an explosion (the region broke through a thin wall into a large region of
values below the threshold), and the flood stops there, answering the last threshold
before it, when it adds

* more voxels than the region's outer shell held when the step began (the voxels next
  to the region not yet in it, the heap): a step moves a partial-volume boundary by a
  fraction of a voxel, so it takes part of that shell, never a bulk of voxels behind it;
* or more than ``ratio - 1`` times the volume grown before it.
"""

from typing import NamedTuple

import numpy as np

from ...jit import njit


class Flood(NamedTuple):
    """The flood's settings (Numba compiles the record as a struct)."""

    sign: float   #: +1 air lumen, -1 contrast lumen: u = sign * value
    u0: float     #: the lowest level checked, u units
    u_max: float  #: never flood past this level
    step: float   #: between checked levels, u units
    ratio: float  #: a step multiplying the volume by more than this is an explosion
    limit: int    #: voxels at the lowest level that mean the region fills the scan


@njit(cache=True)
def _push(keys, vals, n, key, val):
    if n == keys.shape[0]:
        k2 = np.empty(2 * n, np.float64)
        v2 = np.empty(2 * n, np.int64)
        k2[:n] = keys
        v2[:n] = vals
        keys, vals = k2, v2
    i = n
    keys[i] = key
    vals[i] = val
    while i > 0:
        p = (i - 1) >> 1
        if keys[p] <= keys[i]:
            break
        keys[p], keys[i] = keys[i], keys[p]
        vals[p], vals[i] = vals[i], vals[p]
        i = p
    return keys, vals, n + 1


@njit(cache=True)
def _pop(keys, vals, n):
    key, val = keys[0], vals[0]
    n -= 1
    keys[0] = keys[n]
    vals[0] = vals[n]
    i = 0
    while True:
        a = 2 * i + 1
        if a >= n:
            break
        b = a + 1
        c = b if b < n and keys[b] < keys[a] else a
        if keys[i] <= keys[c]:
            break
        keys[c], keys[i] = keys[i], keys[c]
        vals[c], vals[i] = vals[i], vals[c]
        i = c
    return key, val, n


@njit(cache=True)
def flood_levels(data, seed, targets, f, visited, out):
    """Flood from flat index ``seed`` with the settings ``f`` (:class:`Flood`); ``out`` (float64, 5) receives
    ``(threshold, volume, reason, where, beyond)``.

    ``targets`` are sorted flat indices (see the module docstring).
    ``threshold`` is the last checked level (``u`` units) before an explosion, or ``u_max``;
    ``volume`` the voxel count grown at it; ``reason`` 0 (no explosion), 1 (explosion) or
    2 (more than ``limit`` voxels at ``u0`` already); ``where`` the flat index of the voxel
    the explosion was seen at (in the region it broke into; -1 when none) and ``beyond``
    the voxels it had added by then. ``visited`` (uint8, zeroed, the data's shape) marks
    the voxels reached.
    """
    sign, u0, u_max, step, ratio, limit = f.sign, f.u0, f.u_max, f.step, f.ratio, f.limit
    nz, ny, nx = data.shape
    flat = data.ravel()
    vis = visited.ravel()
    keys = np.empty(4096, np.float64)
    vals = np.empty(4096, np.int64)
    n = 0
    vis[seed] = 1
    keys, vals, n = _push(keys, vals, n, max(sign * flat[seed], u0), seed)
    count = 0
    check = u0
    left = targets.shape[0] - int(0.95 * targets.shape[0])  # targets to flood before checking
    before = -1.0  # the volume at the previous checked level
    shell = 0.0  # the heap's size then
    while n > 0:
        level, i, n = _pop(keys, vals, n)
        if left > 0:
            k = np.searchsorted(targets, i)
            if k < targets.shape[0] and targets[k] == i:
                left -= 1
            if left == 0:
                check = max(check, level)
        while left == 0 and level > check:
            before = float(count)
            shell = float(n + 1)
            check += step
        if before < 0.0 and count >= limit:
            out[0], out[1], out[2], out[3], out[4] = u0, float(count), 2.0, -1.0, 0.0
            return
        if before >= 0.0 and (count > ratio * before or count - before > shell):
            out[0], out[1], out[2], out[3], out[4] = check - step, before, 1.0, float(i), count - before
            return
        count += 1
        z = i // (ny * nx)
        r = i - z * ny * nx
        y = r // nx
        x = r - y * nx
        for k in range(6):
            zz, yy, xx = z, y, x
            if k == 0:
                zz -= 1
            elif k == 1:
                zz += 1
            elif k == 2:
                yy -= 1
            elif k == 3:
                yy += 1
            elif k == 4:
                xx -= 1
            else:
                xx += 1
            if zz < 0 or zz >= nz or yy < 0 or yy >= ny or xx < 0 or xx >= nx:
                continue
            j = (zz * ny + yy) * nx + xx
            if vis[j]:
                continue
            u = sign * flat[j]
            if u <= u_max:
                vis[j] = 1
                keys, vals, n = _push(keys, vals, n, max(level, u), j)
    out[0], out[1], out[2], out[3], out[4] = u_max, float(count), 0.0, -1.0, 0.0
