"""The page's region statistics: ``region.json`` answers the statistics of a region drawn on a slice view over the
scan's own voxels (``volumen.measure.roi_stats``), never over the picture or the served copy, and nothing that
names the scan: numbers and units."""

from __future__ import annotations

import json

from aiohttp import web

__all__ = ["region_answer"]

#: the numbers of a region the page is told
FIELDS = ("mean", "sd", "min", "max", "median", "area_mm2", "voxels", "units")


def region_answer(volume, body: bytes) -> bytes:
    """The JSON answer for a ``region.json`` request body; 400 with one line for a bad request or a region that
    holds no voxel of the scan."""
    from volumen.errors import OutsideVolumeError, VolumenError
    from volumen.measure import Plane, roi_stats, shape_from_dict

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
