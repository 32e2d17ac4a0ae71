"""The page's measurements that need the server: ``region.json`` answers the statistics of a region drawn on a slice
view over the scan's own voxels (``volumen.measure.roi_stats``), never over the picture or the served copy;
``pick.json`` the first visible surface under a point of the 3-D picture (``volumen.measure.pick``) in the served
volume, the one the page draws, on the CPU. Nothing that names the scan: numbers and units."""

from __future__ import annotations

import json

import numpy as np
from aiohttp import web

from volumen.core import Camera, Scene
from volumen.errors import OutsideVolumeError, VolumenError
from volumen.measure import Plane, pick, roi_stats, shape_from_dict

from ._requests import BadRequest, frame_request

__all__ = ["region_answer", "pick_answer"]

#: the numbers of a region the page is told
FIELDS = ("mean", "sd", "min", "max", "median", "area_mm2", "voxels", "units")


def region_answer(volume, body: bytes) -> bytes:
    """The JSON answer for a ``region.json`` request body; 400 with one line for a bad request or a region that
    holds no voxel of the scan."""

    try:
        d = json.loads(body)
        plane = Plane.from_dict(d["plane"])
        region = roi_stats(volume, plane, shape_from_dict(d["shape"]))
    except OutsideVolumeError:  # its message names the scan's file: not served
        raise web.HTTPBadRequest(text="the region holds no voxel of the scan") from None
    except (ValueError, KeyError, TypeError, IndexError, AttributeError, VolumenError) as exc:
        text = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise web.HTTPBadRequest(text=text[:200]) from None
    return json.dumps({f: getattr(region, f) for f in FIELDS}).encode()


def pick_answer(volume, body: bytes) -> bytes:
    """The JSON answer for a ``pick.json`` body ``{"frame": {scene, camera, size[, max3d]}, "x", "y"}`` (the frame
    as ``frame.bin`` takes it; ``x``, ``y`` in the picture's pixels): ``{"point": [x, y, z] mm or null}``."""

    try:
        d = json.loads(body)
        req = frame_request(json.dumps(d["frame"]).encode())
        x, y = (float(d[k]) for k in "xy")
        if not all(np.isfinite((x, y))):
            raise ValueError("x and y must be finite numbers (pixels)")
        scene = Scene.from_dict({**req.scene, "volume": ""}, volume=volume)
        point = pick(scene, Camera.from_dict(req.camera), req.size, x, y)
    except (BadRequest, ValueError, KeyError, TypeError, IndexError, AttributeError, VolumenError) as exc:
        text = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise web.HTTPBadRequest(text=text[:200]) from None
    return json.dumps({"point": None if point is None else [float(c) for c in point]}).encode()
