"""Textures of the OpenGL ray caster: the fields of one packed frame (``raycast.Arrays``) on the GPU.

* ``vol``: 3-D R32F of the samples in table units (``(u - sample_offset) * sample_scale``, the
  CPU's ``sample_table``), trilinear, clamped: texel centres are voxel centres;
* no normals: the shader computes them from ``vol`` where it needs them, as the CPU does
  (``_sample.sample_normal``);
* ``rgb``: 3-D RGB8 (normalized) of a colour volume's voxel colours (``raycast._color``), trilinear;
* ``skip_flags`` (R8UI, the eight octants' skip sides side by side: ``raycast._octants.tiled``), ``bmin``, ``bmax``
  (R32F): the block grids of empty-space skipping, read per texel;
* ``lut``, ``extinction``, ``gradient_lut``: one-row 2-D tables read at the nearest entry, ``preintegrated``: the
  pre-integrated table (x: back value, y: front value);
* ``light_data``: the illumination volumes' flat buffer (every light's lattice of light rays,
  ``raycast._lightvol``) as rows of ``width`` values (R32F), read per texel: the shader
  interpolates the lattice exactly as the CPU does (bilinearly between four rays, linearly
  between two slices), which a 3-D texture's filtering could not (the lattice's slices are
  spaced along the light's rays, not on a grid), and any number of lights share one texture.

The per-volume fields and ``light_data`` are kept while the same array objects come
back from the same precomputations (the CPU caches them on the volume), so a new frame of the same volume
uploads only its small tables. :func:`check_limits` raises
:class:`~volumen.errors.DeviceLimitError` for a volume past the context's 3-D texture size
(documented behaviour: a clear error naming the limit and the CPU device, no bricking), and
so does an upload the driver cannot hold.
"""

from __future__ import annotations

import weakref

import numpy as np

from ...errors import DeviceLimitError

__all__ = ["FrameTextures", "check_limits", "release_all"]

#: fields kept between frames while their array object is the same
_KEPT = ("vol", "skip_flags", "bmin", "bmax", "light_data", "rgb")
_kept: dict = {}   # field -> (weakref to the array, texture)


def check_limits(ctx, shape) -> None:
    """Raise :class:`DeviceLimitError` when a ``(nz, ny, nx)`` volume is past the 3-D texture size."""
    limit = int(ctx.info["GL_MAX_3D_TEXTURE_SIZE"])
    if max(shape) > limit:
        z, y, x = shape
        raise DeviceLimitError(f"volume of {z} x {y} x {x} voxels (z, y, x) is past this OpenGL context's 3-D "
                               f"texture limit of {limit} per axis (GL_MAX_3D_TEXTURE_SIZE); use --device cpu")


def _filtered(tex, linear: bool):
    import moderngl

    f = moderngl.LINEAR if linear else moderngl.NEAREST
    tex.filter = (f, f)
    tex.repeat_x = tex.repeat_y = False
    if hasattr(tex, "repeat_z"):
        tex.repeat_z = False
    return tex


def _table_units(u, u0: float, ufac: float) -> np.ndarray:
    """float32 ``(u - u0) * ufac`` of the int16 samples ``u``, in slabs (made without a float64 copy)."""
    out = np.empty(u.shape, np.float32)
    step = max(1, (1 << 22) // max(1, u.shape[1] * u.shape[2]))
    for z0 in range(0, u.shape[0], step):
        s = u[z0:z0 + step].astype(np.float32)
        s -= np.float32(u0)
        s *= np.float32(ufac)
        out[z0:z0 + step] = s
    return out


def _make(ctx, name: str, x: np.ndarray, settings, width: int):
    """A new texture holding field ``name`` = ``x`` of the frame."""
    if name == "vol":
        d = _table_units(x, settings.sample_offset, settings.sample_scale)
        return _filtered(ctx.texture3d(d.shape[::-1], 1, d.tobytes(), dtype="f4", alignment=1), True)
    if name == "rgb":  # uint8 read as normalized [0, 1]
        d = np.ascontiguousarray(x, np.uint8)
        return _filtered(ctx.texture3d(d.shape[2::-1], 3, d.tobytes(), dtype="f1", alignment=1), True)
    if name == "skip_flags":  # the octants' grids side by side
        from ..raycast._octants import tiled  # the raycast package (Numba) loads with the frame

        x = tiled(x)
        return _filtered(ctx.texture3d(x.shape[::-1], 1, np.ascontiguousarray(x, np.uint8).tobytes(),
                                       dtype="u1", alignment=1), False)
    if name in ("bmin", "bmax"):
        return _filtered(ctx.texture3d(x.shape[::-1], 1, np.ascontiguousarray(x, np.float32).tobytes(),
                                       dtype="f4", alignment=1), False)
    if name == "preintegrated":
        n = x.shape[0]
        return _filtered(ctx.texture((x.shape[1], n), 4, np.ascontiguousarray(x, np.float32).tobytes(),
                                     dtype="f4"), False)
    if name == "light_data":
        rows = -(-x.size // width)
        d = np.ones(rows * width, np.float32)
        d[:x.size] = x
        return _filtered(ctx.texture((width, rows), 1, d.tobytes(), dtype="f4"), False)
    d = np.ascontiguousarray(x, np.float32)  # lut (n, 4), extinction (n,), gradient_lut (128,)
    comps = d.shape[1] if d.ndim == 2 else 1
    return _filtered(ctx.texture((d.shape[0], 1), comps, d.tobytes(), dtype="f4"), False)


def _upload(ctx, name, x, settings, width):
    """:func:`_make`, with an out-of-memory answer of the driver turned into :class:`DeviceLimitError`."""
    try:
        return _make(ctx, name, x, settings, width)
    except MemoryError as exc:
        raise DeviceLimitError(f"the {name} texture ({x.nbytes >> 20} MB) does not fit in memory ({exc}); "
                               "use --device cpu") from None
    except Exception as exc:  # noqa: BLE001 - moderngl reports GL_OUT_OF_MEMORY and friends as plain Errors
        raise DeviceLimitError(f"OpenGL could not hold the {name} texture ({x.nbytes >> 20} MB): {exc}; "
                               "use --device cpu") from None


class FrameTextures:
    """The textures of one frame: ``units[name]`` its texture unit; :meth:`release` frees the per-frame ones."""

    FIELDS = ("vol", "lut", "preintegrated", "gradient_lut", "extinction", "skip_flags", "bmin", "bmax", "light_data",
              "rgb")

    def __init__(self, ctx, arrays, settings, prep):
        self.width = int(ctx.info["GL_MAX_TEXTURE_SIZE"])
        if arrays.light_data.size > self.width ** 2:
            raise DeviceLimitError(f"illumination volumes of {arrays.light_data.size} values are past this OpenGL "
                                   f"context's {self.width} x {self.width} 2-D texture limit; use a smaller "
                                   "light_volume_scale, fewer lights, or --device cpu")
        self.own = []
        self.units = {}
        for unit, name in enumerate(self.FIELDS):
            x = getattr(arrays, name)
            tex = self._kept(name, x, prep) if name in _KEPT else None
            if tex is None:
                tex = _upload(ctx, name, x, settings, self.width)
                if name in _KEPT:
                    old = _kept.pop(name, None)
                    if old is not None:
                        old[1].release()
                    _kept[name] = (weakref.ref(x), tex, weakref.ref(prep))
                else:
                    self.own.append(tex)
            tex.use(location=unit)
            self.units[name] = unit

    @staticmethod
    def _kept(name, x, prep):
        """The kept texture of ``x``, while ``x`` and the volume's precomputations ``prep`` are the same objects
        (``render.clear_cache`` after writing into the data makes a new ``prep``, so the data is sent again)."""
        e = _kept.get(name)
        if e is None or e[0]() is not x or e[2]() is not prep:
            return None
        return e[1]

    def release(self) -> None:
        for t in self.own:
            t.release()
        self.own.clear()


def release_all() -> None:
    """Forget the kept textures (``clear_cache``)."""
    for e in _kept.values():
        e[1].release()
    _kept.clear()
