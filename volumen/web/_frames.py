"""Frames for the page: the ray caster's packed frame (``raycast.pack_frame``), as the OpenGL device draws it.

:func:`web_frame` validates a scene and a camera sent by the page (the JSON of ``Scene.to_dict`` and
``Camera.to_dict``), packs the frame with the same code as every device, and returns what the page needs
to draw it with the shared shader: the variant's defines and every uniform
(``raster._rc_uniforms.frame_uniforms``), and the tables, block grids and illumination volumes as typed
arrays (the fields of ``raster._rc_textures.FrameTextures`` but the volume, which the page holds). The page
changes only the camera's and the lights' uniforms between two frames it asks for.

:func:`encode` and the page's ``wire.js`` share one binary layout: ``b"VOLW"``, the header's length
(uint32, little-endian), the header (UTF-8 JSON; ``arrays`` maps each name to its ``dtype``, ``shape``,
``offset`` and ``nbytes``), then each array's bytes at an offset that is a multiple of 8.
"""

from __future__ import annotations

import json
import struct

import numpy as np

from volumen.core import Camera, Scene
from volumen.errors import DeviceLimitError
from volumen.render.raster._rc_uniforms import MAX_LIGHTS, MAX_PLANES, frame_uniforms, variant
from volumen.render.raycast import pack_frame
from volumen.render.raycast._lightvol import light_volumes, plan_lattice
from volumen.render.raycast._octants import tiled
from volumen.render.raycast._params import LV_NK, LV_NU, LV_NV

__all__ = ["web_frame", "encode", "decode", "FrameBudgetError", "FRAME_ARRAYS", "MAGIC"]

MAGIC = b"VOLW"
#: the frame's arrays the page uploads as textures (``FrameTextures.FIELDS`` without the volume's own)
FRAME_ARRAYS = ("lut", "preintegrated", "gradient_lut", "extinction", "skip_flags", "bmin", "bmax", "light_data")
_DTYPES = {"float32": np.float32, "uint8": np.uint8, "float16": np.float16, "int32": np.int32}


class FrameBudgetError(DeviceLimitError):
    """A frame that would need more memory than the server gives one frame (the server answers 413)."""


def _budgeted(budget_bytes: float):
    """``raycast``'s light-volume builder that first sums the illumination volumes the frame's lights would
    need (``plan_lattice``, 4 bytes a node) and raises :class:`FrameBudgetError` past ``budget_bytes``,
    before allocating any."""

    def build(prep, keys, positions_index, box_lo, box_hi, *rest):
        scale, method = rest[-2], rest[-1]
        if method != "direct":
            nodes = 0
            for p in positions_index[:len(keys)]:
                m = plan_lattice(p, box_lo, box_hi, prep.u.shape, scale)
                nodes += 0 if m is None else int(m[LV_NK] * m[LV_NV] * m[LV_NU])
            if 4 * nodes > budget_bytes:
                raise FrameBudgetError(
                    f"{len(keys)} shadowed lights need {4 * nodes / 2**20:.0f} MiB of illumination volumes; a frame "
                    f"may use {budget_bytes / 2**20:.0f} MiB: use fewer shadowed lights or a lower "
                    "light_volume_scale")
        return light_volumes(prep, keys, positions_index, box_lo, box_hi, *rest)

    return build


def _check(scene: Scene) -> None:

    if scene.shading.mode == "pathtrace" and scene.mode == "composite":
        raise DeviceLimitError("path tracing is not drawn by the browser viewer (it runs on the cpu and cuda "
                               "devices); pick another shading")
    if len(scene.lights) > MAX_LIGHTS and scene.shading.mode not in ("none", "headlight"):
        raise DeviceLimitError(f"{len(scene.lights)} lights: the viewer takes at most {MAX_LIGHTS}")
    if len(scene.clipping.planes) > MAX_PLANES:
        raise DeviceLimitError(f"{len(scene.clipping.planes)} clip planes: the viewer takes at most {MAX_PLANES}")


def _plain(value):
    """A uniform's value as JSON: numbers, booleans, flat lists."""
    if isinstance(value, np.ndarray):
        return value.ravel().tolist()
    if isinstance(value, tuple):
        return list(value)
    return value


def web_frame(volume, scene_dict: dict, camera_dict: dict, size, budget_bytes: float = float("inf")
              ) -> tuple[dict, dict]:
    """``(header, arrays)`` of the frame of ``scene_dict`` (its volume replaced by ``volume``) seen by
    ``camera_dict`` in a picture of ``size = (width, height)``, its illumination volumes within ``budget_bytes``.

    Raises
    ------
    ValueError
        For a scene or camera that does not validate (the message names the field).
    DeviceLimitError
        For what the viewer does not draw (path tracing, more lights or clip planes than a pass takes);
        :class:`FrameBudgetError` for illumination volumes past ``budget_bytes``.
    """

    w, h = (int(v) for v in size)
    if not (1 <= w <= 8192 and 1 <= h <= 8192):
        raise ValueError(f"picture size must be 1..8192 pixels a side, got {w} x {h}")
    scene = Scene.from_dict({**scene_dict, "volume": ""}, volume=volume)
    camera = Camera.from_dict(camera_dict)
    _check(scene)
    f = pack_frame(scene, camera, (w, h), build_light_volumes=_budgeted(budget_bytes))
    arrays = {name: np.ascontiguousarray(getattr(f.arrays, name)) for name in FRAME_ARRAYS}
    arrays["light_data"] = arrays["light_data"].astype(np.float32, copy=False).ravel()
    arrays["skip_flags"] = tiled(arrays["skip_flags"])  # the octants' grids side by side, as the gl device's texture
    header = {"defines": variant(f), "uniforms": {k: _plain(v) for k, v in frame_uniforms(f).items()},
              "display": scene.display.resolved(scene.shading.mode, scene.mode).to_dict(),
              "lights_built": int(f.light_volumes_built),
              "timings": {k: round(float(v), 6) for k, v in f.timings.items()}}
    return header, arrays


def encode(header: dict, arrays: dict) -> bytes:
    """The binary message of ``header`` and ``arrays`` (see the module's docstring)."""
    table, blobs, offset = {}, [], 0
    for name, a in arrays.items():
        a = np.ascontiguousarray(a)
        if a.dtype.name not in _DTYPES:
            raise ValueError(f"array {name!r} of dtype {a.dtype} cannot be sent; valid: {', '.join(_DTYPES)}")
        table[name] = {"dtype": a.dtype.name, "shape": list(a.shape), "offset": offset, "nbytes": a.nbytes}
        pad = -a.nbytes % 8
        blobs += [a.reshape(-1).view(np.uint8), b"\0" * pad]   # the array's own bytes: one copy, in the join
        offset += a.nbytes + pad
    text = json.dumps({**header, "arrays": table}, separators=(",", ":")).encode()
    text += b" " * (-(len(text) + 8) % 8)  # the arrays start at a multiple of 8
    return b"".join([MAGIC, struct.pack("<I", len(text)), text, *blobs])


def decode(message: bytes) -> tuple[dict, dict]:
    """Inverse of :func:`encode` (tests and tools read what the page reads)."""
    if message[:4] != MAGIC:
        raise ValueError("not a volumen web message")
    (n,) = struct.unpack("<I", message[4:8])
    header = json.loads(message[8:8 + n])
    base = 8 + n
    arrays = {}
    for name, d in header.pop("arrays").items():
        raw = message[base + d["offset"]:base + d["offset"] + d["nbytes"]]
        arrays[name] = np.frombuffer(raw, _DTYPES[d["dtype"]]).reshape(d["shape"])
    return header, arrays
