"""A single slice drawn as the slab it stands for, by every drawing path (``render``, ``PathTracer``).

A volume is drawn between its voxel centres, so an axis of one sample spans nothing: a ray through it composites
nothing. :meth:`Volume.slab <volumen.core.Volume.slab>` repeats the sample half a spacing (the slice thickness)
either side of it; :func:`slabbed` puts what else the scene holds on the volume's grid there too: its label layer
and a crop box in voxel indices.
"""

from __future__ import annotations

import weakref
from dataclasses import replace

__all__ = ["slabbed", "kept_for"]

_SLABS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def slabbed(scene):
    """``scene`` with a single slice's volume, labels and voxel crop on its slab's grid (a chunked plane's a lazy
    view, read as the plane); ``scene`` itself for a volume with no axis of one sample."""
    vol = scene.volume
    if vol is None or 1 not in vol.shape:
        return scene
    changes = {"volume": _slab_volume(vol)}
    layer = scene.labels
    if layer is not None and layer.labels.shape == vol.shape:
        changes["labels"] = replace(layer, labels=layer.labels.slab())
    clip = scene.clipping
    if clip.crop is not None and clip.crop_space == "voxel":
        changes["clipping"] = replace(clip, crop=_slab_crop(clip.crop, vol.shape))
    return scene.with_(**changes)


def kept_for(store: weakref.WeakKeyDictionary, volume, make):
    """``make(volume)``, a volume derived from ``volume``, kept in ``store`` while the volume and its data live
    (made again when its data array is replaced)."""
    kept = store.get(volume)
    if kept is None or kept[0] is not volume.data:
        kept = (volume.data, make(volume))
        store[volume] = kept
    return kept[1]


def _slab_volume(volume):
    """:meth:`Volume.slab` of a single slice, kept while the volume and its data live."""
    return kept_for(_SLABS, volume, lambda v: v.slab())


def _slab_crop(crop, shape):
    """A voxel crop ``(xmin, xmax, ymin, ymax, zmin, zmax)`` of the volume's indices on its slab's: along an axis
    of one sample, ``[lo, hi]`` covers voxels lo .. hi, each reaching half a spacing either side of its centre,
    which is ``[lo, hi + 1]`` in the slab's indices (its first sample lies half a spacing before the volume's)."""
    box = list(crop)
    for axis, n in enumerate(shape):  # array axes (z, y, x): crop pairs 4-5, 2-3, 0-1
        if n == 1:
            box[2 * (2 - axis) + 1] += 1.0
    return tuple(box)
