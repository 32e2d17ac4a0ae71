"""GPU copies of volumes and transfer functions, made once and kept for the next frames.

* value texture: 3-D, one float32 channel, the data mapped linearly so the
  volume's value range ``[vmin, vmax]`` becomes [0, 1] (NaN -> 0), trilinear,
  clamped at the edges; texel centres are voxel centres, so texture coordinate
  ``(i + 0.5) / nx`` is voxel index ``i`` (the ray caster's convention).
* classified texture (pre-classification): 3-D RGBA half floats, the transfer
  function applied to every voxel, colour premultiplied by the opacity per
  reference step; interpolated after classification.
* transfer-function texture: ``(NLUT x 1)`` RGBA float32 (OpenGL 1-D textures
  are not in moderngl; a one-row 2-D texture is the same thing), straight
  colour and opacity per reference step over ``[vmin, vmax]``, read at the
  nearest entry like the ray caster's table.

Volumes are cached by identity (the last three), keyed also on their data
array and affine so a new array is noticed; :func:`clear_cache` forgets them.
"""

from __future__ import annotations

import weakref
from collections import OrderedDict

import numpy as np

from ...core import drawable_range, table_range
from ._context import gl_thread

__all__ = ["NLUT", "value_range", "value_texture", "classified_texture", "tf_texture", "clear_cache"]

#: entries of the transfer-function texture (as the ray caster's table)
NLUT = 4096
_MAX_VOLUMES = 3
_volumes: OrderedDict = OrderedDict()   # id(volume) -> _Entry
_tfs: OrderedDict = OrderedDict()       # (tf json, vmin, vmax) -> texture


class _Entry:
    def __init__(self, volume, key):
        self.ref = weakref.ref(volume)
        self.key = key
        self.value = None
        self.classified: OrderedDict = OrderedDict()

    def release(self) -> None:
        for t in [self.value, *self.classified.values()]:
            if t is not None:
                t.release()
        self.classified.clear()
        self.value = None


def _key(volume) -> tuple:
    d = volume.data
    return (id(d), d.shape, d.dtype.str, np.asarray(volume.affine, float).tobytes())


def value_range(volume) -> tuple[float, float]:
    """``(vmin, vmax)`` the textures map to [0, 1] (values past it clamped): the finite data range less an MRI's
    far outliers (``core.table_range``, as the ray caster's table), widened to 1 unit when flat."""
    return drawable_range(*table_range(volume))


def _entry(volume) -> _Entry:
    k = id(volume)
    e = _volumes.get(k)
    if e is not None and (e.ref() is not volume or e.key != _key(volume)):
        e.release()
        del _volumes[k]
        e = None
    if e is None:
        e = _volumes[k] = _Entry(volume, _key(volume))
        while len(_volumes) > _MAX_VOLUMES:
            _volumes.popitem(last=False)[1].release()
    _volumes.move_to_end(k)
    return e


def _normalized(volume, z0: int, z1: int) -> np.ndarray:
    vmin, vmax = value_range(volume)
    u = (volume.data[z0:z1].astype(np.float32) - np.float32(vmin)) * np.float32(1.0 / (vmax - vmin))
    return np.clip(np.nan_to_num(u, nan=0.0), 0.0, 1.0)


def _texture3d(ctx, shape, components, dtype, data: bytes):
    nz, ny, nx = shape
    tex = ctx.texture3d((nx, ny, nz), components, data, dtype=dtype, alignment=1)
    tex.repeat_x = tex.repeat_y = tex.repeat_z = False
    import moderngl

    tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
    return tex


def value_texture(ctx, volume):
    """The volume's normalized value texture (R32F, ``[vmin, vmax]`` -> [0, 1]), made on first use."""
    e = _entry(volume)
    if e.value is None:
        e.value = _texture3d(ctx, volume.shape, 1, "f4", _normalized(volume, 0, volume.shape[0]).tobytes())
    return e.value


def classified_texture(ctx, volume, tf):
    """Pre-classified RGBA16F texture of ``volume`` under ``tf`` (premultiplied, opacity per reference step)."""
    e = _entry(volume)
    key = tf.to_json()
    tex = e.classified.get(key)
    if tex is None:
        vmin, vmax = value_range(volume)
        lut = tf.lut(vmin, vmax, NLUT).astype(np.float32)
        lut[:, :3] *= lut[:, 3:4]
        out = np.empty(volume.shape + (4,), np.float16)
        step = max(1, (1 << 22) // max(1, volume.shape[1] * volume.shape[2]))
        for z0 in range(0, volume.shape[0], step):  # slabs of ~4 M voxels keep the memory small
            idx = np.rint(_normalized(volume, z0, z0 + step) * (NLUT - 1)).astype(np.int32)
            out[z0:z0 + step] = lut[idx]
        tex = e.classified[key] = _texture3d(ctx, volume.shape, 4, "f2", out.tobytes())
        while len(e.classified) > 2:
            e.classified.popitem(last=False)[1].release()
    return tex


def tf_texture(ctx, tf, vmin: float, vmax: float):
    """``(NLUT x 1)`` RGBA32F table of ``tf`` over ``[vmin, vmax]`` (straight colour), nearest filtering."""
    key = (tf.to_json(), float(vmin), float(vmax))
    tex = _tfs.get(key)
    if tex is None:
        import moderngl

        lut = np.ascontiguousarray(tf.lut(vmin, vmax, NLUT), np.float32)
        tex = _tfs[key] = ctx.texture((NLUT, 1), 4, lut.tobytes(), dtype="f4")
        tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
        tex.repeat_x = tex.repeat_y = False
        while len(_tfs) > 8:
            _tfs.popitem(last=False)[1].release()
    _tfs.move_to_end(key)
    return tex


@gl_thread
def clear_cache(volume=None) -> None:
    """Release the GPU copies of ``volume`` (or of every volume and transfer function)."""
    if volume is None:
        from ._rc_textures import release_all

        release_all()
        for e in _volumes.values():
            e.release()
        _volumes.clear()
        for t in _tfs.values():
            t.release()
        _tfs.clear()
    else:
        e = _volumes.pop(id(volume), None)
        if e is not None:
            e.release()
