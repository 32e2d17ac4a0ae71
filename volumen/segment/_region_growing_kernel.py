"""Compiled flood fill for ``_region_growing.py`` (arrays and scalars only).

Breadth-first from the seeds over voxels whose value lies in ``[lo, hi]``; the queue
is a ring buffer of flat indices that doubles when full, so memory follows the
front, not the volume.
"""


import numpy as np

from ..jit import njit


@njit(cache=True)
def flood(vol, lo, hi, seeds, offsets, out):
    """Mark in ``out`` (uint8, zeroed, shape of ``vol``) the voxels connected to the seeds.

    ``seeds`` (n, 3) and ``offsets`` (k, 3) are ``[z, y, x]``; seeds outside the range are
    skipped. Returns the number of voxels marked.
    """
    nz, ny, nx = vol.shape
    flat = vol.ravel()
    mark = out.ravel()
    cap = 1 << 16
    queue = np.empty(cap, np.int64)
    head = 0
    size = 0
    count = 0
    for s in range(seeds.shape[0]):
        i = (seeds[s, 0] * ny + seeds[s, 1]) * nx + seeds[s, 2]
        v = flat[i]
        if mark[i] == 0 and v >= lo and v <= hi:
            mark[i] = 1
            count += 1
            if size == cap:
                queue, head, cap = _grow(queue, head, cap)
            queue[(head + size) & (cap - 1)] = i
            size += 1
    while size > 0:
        i = queue[head]
        head = (head + 1) & (cap - 1)
        size -= 1
        z = i // (ny * nx)
        rem = i - z * ny * nx
        y = rem // nx
        x = rem - y * nx
        for k in range(offsets.shape[0]):
            zz = z + offsets[k, 0]
            yy = y + offsets[k, 1]
            xx = x + offsets[k, 2]
            if zz < 0 or zz >= nz or yy < 0 or yy >= ny or xx < 0 or xx >= nx:
                continue
            j = (zz * ny + yy) * nx + xx
            if mark[j]:
                continue
            v = flat[j]
            if v >= lo and v <= hi:
                mark[j] = 1
                count += 1
                if size == cap:
                    queue, head, cap = _grow(queue, head, cap)
                queue[(head + size) & (cap - 1)] = j
                size += 1
    return count


@njit(cache=True)
def _grow(queue, head, cap):
    """Double a full ring buffer, unrolling it so the front is at index 0."""
    bigger = np.empty(2 * cap, np.int64)
    n = cap - head
    bigger[:n] = queue[head:]
    bigger[n:cap] = queue[:head]
    return bigger, 0, 2 * cap
