"""The page's measurements that need the server: ``region.json`` answers the statistics of a region drawn on a slice
view over the scan's own voxels (``volumen.measure.roi_stats``), never over the picture or the served copy;
``value.json`` the scan's own value at a point (``volumen.measure.point_value``); ``open-measurements.json`` the
measurements of a file the user opens on the page (a DICOM SR, a session or a measurements JSON), refused where
they belong to another study or scan; ``pick.json`` the first visible
surface under a point of the 3-D picture (``volumen.measure.pick``) in the served volume, the one the page draws,
on the CPU. Nothing that names the scan: numbers and units."""

from __future__ import annotations

import json
import os
import tempfile

import highdicom  # noqa: F401 - with the server, not in a request thread: reading an SR needs it
import numpy as np
from aiohttp import web

from volumen import pacs  # noqa: F401 - likewise: an SR's study is checked against the scan's files
from volumen.core import Camera, Scene
from volumen.errors import MeasurementError, OutsideVolumeError, VolumenError
from volumen.measure import (
    Plane,
    _sr_read,  # noqa: F401 - likewise: the SR reader itself
    check_scan,
    check_study,
    pick,
    point_value,
    read_measurements,
    roi_stats,
    shape_from_dict,
)

from ._requests import BadRequest, frame_request

__all__ = ["region_answer", "value_answer", "measurements_answer", "pick_answer"]

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


def value_answer(volume, body: bytes) -> bytes:
    """The JSON answer for a ``value.json`` body ``{"point": [x, y, z]}`` (world mm): ``{"value", "units"}`` of the
    scan's voxel nearest it, or null outside the scan; 400 with one line for a bad request."""

    try:
        point = np.asarray(json.loads(body)["point"], dtype=float)
        if point.shape != (3,) or not np.all(np.isfinite(point)):
            raise ValueError("point must be three finite numbers (mm)")
        found = point_value(volume, point)
    except (ValueError, KeyError, TypeError, IndexError, AttributeError) as exc:
        text = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise web.HTTPBadRequest(text=text[:200]) from None
    return json.dumps(None if found is None else {"value": found[0], "units": found[1]}).encode()


def _read_body(body: bytes):
    """The measurements of a file's bytes and its study UID (an SR's; "" for JSON)."""
    fd, path = tempfile.mkstemp(prefix="volumen-measurements-")
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(body)
        return read_measurements(path)
    finally:
        os.unlink(path)


def measurements_answer(volume, body: bytes) -> bytes:
    """The JSON answer for an ``open-measurements.json`` body (the bytes of a DICOM SR, a session or a measurements
    JSON): ``{"measurements": [...]}`` as ``Measurements.to_dicts``; 400 with one line that names neither file nor
    scan for a file that holds none, an SR of another study, measurements of another scan."""

    try:
        items, study = _read_body(body)
    except (MeasurementError, ValueError, KeyError, TypeError, AttributeError) as exc:
        raise web.HTTPBadRequest(text=f"the file holds no measurements volumen reads ({type(exc).__name__})"
                                 ) from None
    try:
        check_study(study, volume, "the SR") if study else None
    except MeasurementError:
        raise web.HTTPBadRequest(text="the SR is of another study than the scan shown") from None
    try:
        check_scan(items, volume)
    except MeasurementError:
        raise web.HTTPBadRequest(text="the measurements were made on another scan than the one shown") from None
    return json.dumps({"measurements": items.to_dicts()}).encode()


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
