"""Illumination volumes: per-light transmittance on a lattice of light rays, swept once, read per sample.

Each light gets a lattice of rays from the light through the drawn region,
built by a compiled sweep over the slices of the volume along the axis the
light looks down (the slices nearest the light first, every ray in parallel).
Along each ray the optical depth is accumulated exactly as a direct shadow
ray does (:mod:`._shadow`: trapezoid rule on the transfer function's optical
depth of trilinear samples, partial segments where the ray enters and leaves
the drawn region, extra samples where the ray crosses slices obliquely), and
the transmittance ``exp(-kext tau)`` is stored where the ray crosses each
slice. Because every stored value lies on one exact ray, there is no
slice-to-slice resampling, hence no numerical blur of the shadows with
distance: a lookup interpolates once (bilinearly between four rays, linearly
between two slices).

Geometry. Data axes are (0, 1, 2) = (z, y, x). With ``a`` the sweep axis and
``b < c`` the other two, the light is at ``P`` (index coordinates along
(a, b, c)) outside the slab of slices ``k0 .. k0 + nk - 1`` along ``a``; the
ray of lattice node ``(v, u)`` goes from ``P`` through ``Q = (kfar, ov + v h,
ou + u h)`` on the far slice ``kfar``, and crosses slice ``k`` at
``P + s (Q - P)`` with ``s = (k - Pa) / (kfar - Pa)``. The lattice spacing is
``h`` voxels on the far slice (finer on nearer slices) and covers every point
of the region; ``h = 1 / light_volume_scale``, coarser when the light is so
near that the lattice would fan out past ``BUDGET`` times the region's nodes, or
past ``NODE_SHARE`` nodes a voxel of the volume (:func:`light_nodes`: float32 nodes, a quarter of an int16
volume's bytes a light; the light varies slowly across the coarser spacing this gives a large volume, whose
voxels are small against its shadows). Lights inside the region's box on every axis have no
lattice: their visibility falls back to direct shadow rays (``LV_KIND = DIRECT``).

Near the sample, surfaces lie within one lattice spacing of the path to the
light, where any interpolated volume smears them (a lit surface would shadow
itself): the first ``NEAR_STEPS`` reference steps of each path are marched
directly (:mod:`._shadow`), and the volume is read where they end. A path finds that place first
(:func:`lattice_site`), asks the cache for its node rows (:func:`lattice_ahead`), marches, and then reads them
(:func:`lattice_read`): three lights' lattices of the whole-abdomen CT are 780 MB, read at random, and their
reads waited on memory (a scattering frame took about 0.9x the time once the rows were asked for first, with the
same values).

The volumes are cached on the volume's ``Prepared`` object, keyed by the
light's world position, the transfer function, the clip box, the resolution,
the extinction scale and the label map with its table (a structure shown,
hidden or recoloured casts its own shadows: the sweep reads the medium of
:mod:`._medium`), and rebuilt only when one of those changes.
"""

from __future__ import annotations

import math
import time

import numpy as np

from ...jit import njit, prefetch
from ._lightsweep import (
    build_lattice,
    lattice_frame,
    lattice_offsets,
    lattice_ray,
    lattice_slice,
    lattice_step,
    lattice_transmittance_of,
)

__all__ = ["LV_KIND", "LATTICE", "DIRECT", "NMETA", "NEAR_STEPS", "NO_SITE", "plan_lattice", "build_lattice",
           "lattice_site", "lattice_read", "lattice_ahead", "light_volumes", "light_nodes",
           "lattice_frame", "lattice_offsets", "lattice_ray", "lattice_slice", "lattice_step",
           "lattice_transmittance_of"]

from ._params import (
    BUDGET,
    DIRECT,
    LATTICE,
    LV_AXA,
    LV_AXB,
    LV_AXC,
    LV_H,
    LV_K0,
    LV_KFAR,
    LV_KIND,
    LV_NK,
    LV_NU,
    LV_NV,
    LV_OFF,
    LV_OU,
    LV_OV,
    LV_PA,
    LV_PB,
    LV_PC,
    MIN_NODES,
    NEAR_STEPS,
    NMETA,
    NODE_SHARE,
)


@njit(cache=True, fastmath=True)
def _pick(ax, x, y, z):
    """Index coordinate along data axis ``ax`` (0: z, 1: y, 2: x)."""
    if ax == 0:
        return z
    if ax == 1:
        return y
    return x


@njit(cache=True, fastmath=True)
def _slice_node(grid, q, at):
    """``(index in the slice of the lower node, fu, fv)`` where the ray through the position crosses a slice, in node
    units ``u = uc + dc q``, ``v = ub + db q`` (:func:`lattice_site`; ``grid = (nv, nu)``, ``at = (ub, uc, db, dc)``,
    ``db``, ``dc`` the position less the light along b, c); index -1 outside the lattice (transmittance 1 there)."""
    nv, nu = grid
    ub, uc, db, dc = at
    u = uc + dc * q
    v = ub + db * q
    if not (u >= 0.0 and v >= 0.0 and u <= nu - 1 and v <= nv - 1):
        return -1, 0.0, 0.0
    u0 = min(int(u), nu - 2)
    v0 = min(int(v), nv - 2)
    return v0 * nu + u0, u - u0, v - v0


@njit(cache=True, fastmath=True, inline="always")
def _node_value(lvd, i, nu, fu, fv):
    """Bilinear between the four nodes from flat index ``i`` (rows ``nu`` apart); 1 where ``i < 0``."""
    if i < 0:
        return 1.0
    r0 = lvd[i] + fu * (lvd[i + 1] - lvd[i])
    r1 = lvd[i + nu] + fu * (lvd[i + nu + 1] - lvd[i + nu])
    return r0 + fv * (r1 - r0)


#: a site that reads nothing (:func:`lattice_site`'s record; transmittance 1)
NO_SITE = (-1, 0.0, 0.0, -1, 0.0, 0.0, 0.0, 0)


@njit(cache=True, fastmath=True)
def lattice_site(lvm, li, x, y, z):
    """Where the transmittance toward light ``li`` at voxel-index position (x, y, z) is read from its lattice
    (:func:`lattice_read`; :func:`lattice_ahead` asks the cache for it first): ``(i0, fu0, fv0, i1, fu1, fv1, w,
    nu)``, the flat indices into ``lvd`` of the lower nodes on the two slices around the position (-1:
    transmittance 1) with their fractions, the weight ``w`` of the second slice (0: the first alone) and the
    rows' length."""
    ca = _pick(int(lvm[li, LV_AXA]), x, y, z)
    cb = _pick(int(lvm[li, LV_AXB]), x, y, z)
    cc = _pick(int(lvm[li, LV_AXC]), x, y, z)
    nk = int(lvm[li, LV_NK])
    nv = int(lvm[li, LV_NV])
    nu = int(lvm[li, LV_NU])
    pa = lvm[li, LV_PA]
    kfar = lvm[li, LV_KFAR]
    k0 = lvm[li, LV_K0]
    kf = ca - k0
    low = pa < k0  # light on the low-index side
    if (kf < 0.0 and low) or (kf > nk - 1 and not low):  # before the lattice, seen from the light
        return -1, 0.0, 0.0, -1, 0.0, 0.0, 0.0, nu
    kf = min(max(kf, 0.0), nk - 1.0)
    i0 = min(int(kf), max(nk - 2, 0))
    i1 = min(i0 + 1, nk - 1)
    w = kf - i0
    off = int(lvm[li, LV_OFF])
    pb = lvm[li, LV_PB]
    pc = lvm[li, LV_PC]
    ov = lvm[li, LV_OV]
    ou = lvm[li, LV_OU]
    h = lvm[li, LV_H]
    # the ray from P through the position crosses slice k at b = pb + (cb - pb) / s_k, s_k = (k - pa) / (kfar - pa):
    # in node units (b - ov) / h = ub + (cb - pb) q_k, with q_k = (kfar - pa) / ((k - pa) h), one division a slice
    ih = 1.0 / h
    ub = (pb - ov) * ih
    uc = (pc - ou) * ih
    ph = (kfar - pa) * ih
    at = (ub, uc, cb - pb, cc - pc)
    n0, fu0, fv0 = _slice_node((nv, nu), ph / (k0 + i0 - pa), at)
    if w <= 0.0 or i1 == i0:
        return (n0 + off + i0 * nv * nu if n0 >= 0 else -1), fu0, fv0, -1, 0.0, 0.0, 0.0, nu
    n1, fu1, fv1 = _slice_node((nv, nu), ph / (k0 + i1 - pa), at)
    return ((n0 + off + i0 * nv * nu if n0 >= 0 else -1), fu0, fv0, (n1 + off + i1 * nv * nu if n1 >= 0 else -1),
            fu1, fv1, w, nu)


@njit(cache=True, fastmath=True, inline="always")
def lattice_ahead(lvd, site):
    """Ask the cache for the node rows :func:`lattice_read` will read at ``site`` (``volumen.jit.prefetch``)."""
    i0, _, _, i1, _, _, w, nu = site
    if i0 >= 0:
        prefetch(lvd, i0)
        prefetch(lvd, i0 + nu)
    if w > 0.0 and i1 >= 0:
        prefetch(lvd, i1)
        prefetch(lvd, i1 + nu)


@njit(cache=True, fastmath=True)
def lattice_read(lvd, site):
    """The transmittance at ``site`` (:func:`lattice_site`): bilinear on each slice, linear between the two."""
    i0, fu0, fv0, i1, fu1, fv1, w, nu = site
    t0 = _node_value(lvd, i0, nu, fu0, fv0)
    if w <= 0.0:
        return t0
    t1 = _node_value(lvd, i1, nu, fu1, fv1)
    return t0 + w * (t1 - t0)


def plan_lattice(light_index, box_lo, box_hi, shape, scale: float):
    """The lattice geometry for a light, or None when the light is inside the region's box on every axis.

    Parameters
    ----------
    light_index : (3,) float
        The light's position in voxel indices (x, y, z).
    box_lo, box_hi : (3,) float
        The drawn region's box in voxel indices (x, y, z) (volume box with the crop).
    shape : (nz, ny, nx)
    scale : float
        Requested resolution: lattice spacing ``1 / scale`` voxels on the far slice.

    Returns
    -------
    meta : (NMETA,) float64 or None
        ``LV_*`` entries (``LV_OFF`` left 0), for the sweep axis that gives the
        finest lattice within the budget (then the smallest).
    """
    p = np.asarray(light_index, float)[::-1]  # data-axis order (z, y, x)
    lo = np.asarray(box_lo, float)[::-1]
    hi = np.asarray(box_hi, float)[::-1]
    best = None
    top = light_nodes(shape)
    for a in range(3):
        b, c = [d for d in range(3) if d != a]
        k0 = max(int(math.floor(lo[a] + 1e-9)), 0)
        k1 = min(int(math.ceil(hi[a] - 1e-9)), shape[a] - 1)
        if p[a] < k0 - 0.25:
            near, far = k0, k1
        elif p[a] > k1 + 0.25:
            near, far = k1, k0
        else:
            continue
        smin = (near - p[a]) / (far - p[a])
        h = 1.0 / scale
        ext = []
        for d in (b, c):
            e0 = min(lo[d], p[d] + (lo[d] - p[d]) / smin)
            e1 = max(hi[d], p[d] + (hi[d] - p[d]) / smin)
            ext.append((e0, e1))
        area = (ext[0][1] - ext[0][0]) * (ext[1][1] - ext[1][0])
        region = max(hi[b] - lo[b] + 1, 1) * max(hi[c] - lo[c] + 1, 1)
        if area / h ** 2 > BUDGET * region * scale ** 2:
            h *= math.sqrt(area / h ** 2 / (BUDGET * region * scale ** 2))
        nk = k1 - k0 + 1
        if nk * area / h ** 2 > top:
            h = math.sqrt(nk * area / top)
        nv = int(math.ceil((ext[0][1] - ext[0][0]) / h)) + 3
        nu = int(math.ceil((ext[1][1] - ext[1][0]) / h)) + 3
        rank = (round(h, 6), nk * nv * nu)  # the finest lattice, then the smallest
        if best is None or rank < best[0]:
            m = np.zeros(NMETA)
            m[LV_KIND] = LATTICE
            m[[LV_NK, LV_NV, LV_NU]] = nk, nv, nu
            m[[LV_AXA, LV_AXB, LV_AXC]] = a, b, c
            m[[LV_PA, LV_PB, LV_PC]] = p[a], p[b], p[c]
            m[LV_KFAR], m[LV_K0] = far, k0
            m[LV_OV], m[LV_OU], m[LV_H] = ext[0][0] - h, ext[1][0] - h, h
            best = (rank, m)
    return None if best is None else best[1]


def light_nodes(shape) -> float:
    """The most nodes one light's lattice may hold for a volume of ``shape``: :data:`NODE_SHARE` a voxel, and
    never fewer than :data:`MIN_NODES`."""
    return max(NODE_SHARE * float(np.prod(shape)), float(MIN_NODES))


class _Set:
    """The illumination volumes of one set of lights: packed meta rows and one flat buffer."""

    def __init__(self, keys, lvm, lvd, views):
        self.keys, self.lvm, self.lvd, self.views = keys, lvm, lvd, views


def light_volumes(prep, keys, positions_index, box_lo, box_hi, med, geo, planes, nplanes, ds0, kext, scale,
                  method: str):
    """Meta rows ``(n, NMETA)`` float64 and the flat float32 buffer of every light's illumination volume.

    Parameters
    ----------
    prep : Prepared
        The volume's cache (``prep.u``, ``prep.affine``); the set is kept on it.
    keys : list of hashable
        One key per light: what its volume depends on (position, transfer
        function, clip box, resolution, extinction scale).
    positions_index : (n, 3) float
        Light positions in voxel indices (x, y, z).
    med : Medium
        What the light paths cross (``_medium``: ``prep.u`` and its optical depth, or the label-aware
        classification).
    method : {"fast", "direct"}
        ``direct`` marks every light DIRECT and builds nothing.

    Returns
    -------
    lvm, lvd, built : meta rows, buffer, and the number of volumes built now (with their seconds in
    ``prep.timings["light_volumes"]``).
    """
    n = len(keys)
    if method == "direct" or n == 0:
        lvm = np.zeros((max(n, 1), NMETA))
        lvm[:n, LV_KIND] = DIRECT
        return lvm, np.ones(1, np.float32), 0
    old = getattr(prep, "light_set", None)
    if old is not None and old.keys == tuple(keys):
        return old.lvm, old.lvd, 0
    olds = {} if old is None else dict(zip(old.keys, old.views, strict=True))
    metas = []
    off = 0
    for i in range(n):
        if keys[i] in olds:
            m = olds[keys[i]][0].copy()
        else:
            m = plan_lattice(positions_index[i], box_lo, box_hi, prep.u.shape, scale)
        if m is None:
            m = np.zeros(NMETA)
            m[LV_KIND] = DIRECT
        else:
            m[LV_OFF] = off
            off += int(m[LV_NK] * m[LV_NV] * m[LV_NU])
        metas.append(m)
    lvd = np.ones(max(off, 1), np.float32)
    views = []
    built = 0
    t = time.perf_counter()
    for i, m in enumerate(metas):
        view = None
        if m[LV_KIND] == LATTICE:
            o = int(m[LV_OFF])
            shape = tuple(int(m[j]) for j in (LV_NK, LV_NV, LV_NU))
            view = lvd[o:o + int(np.prod(shape))].reshape(shape)
            if keys[i] in olds and olds[keys[i]][1] is not None:
                view[...] = olds[keys[i]][1]
            else:
                build_lattice(med, prep.affine, geo, planes, nplanes, m, ds0, kext, out=view)
                built += 1
        views.append((m, view))
    if built:
        prep.timings["light_volumes"] = time.perf_counter() - t
    lvm = np.stack(metas)
    prep.light_set = _Set(tuple(keys), lvm, lvd, views)
    return lvm, lvd, built
