"""Measurements in world millimetres: points, distances, angles, regions with statistics, structure volumes.

The model is independent of any viewer: the app, the browser page, the headset and a notebook make the same
objects, save them in a session (:mod:`._persistence`) and exchange them as a DICOM Comprehensive 3D SR
(:mod:`._sr_write`, :mod:`._sr_read`). Notebook use::

    from volumen import measure
    measure.distance((0, 0, 0), (30, 40, 0))                  # 50.0 mm, shown as a table
    measure.roi_stats(ct, measure.slice_plane(ct, "axial", 40), measure.Ellipse((0, 0), (10, 6)))
    measure.label_volumes(labels)                             # ml per structure
"""

from __future__ import annotations

from ._label_volumes import label_volumes
from ._model import KINDS, Angle, Distance, LabelVolume, Measurements, Point, RegionStats, Scan, from_dict
from ._persistence import SESSION_KEY, check_scan, load_measurements, save_measurements, session_measurements
from ._plane_shapes import SHAPES, Ellipse, Plane, Polygon, Rectangle, shape_from_dict, slice_plane
from ._regions import region_voxels, roi_stats

__all__ = ["Plane", "Ellipse", "Rectangle", "Polygon", "SHAPES", "shape_from_dict", "slice_plane", "Scan", "Point",
           "Distance", "Angle", "RegionStats", "LabelVolume", "Measurements", "KINDS", "from_dict", "distance", "angle",
           "point", "roi_stats", "region_voxels", "label_volumes", "load_measurements", "save_measurements",
           "session_measurements", "check_scan", "SESSION_KEY", "make_sr", "pick"]


def distance(p, q, volume=None, label: str = "") -> Distance:
    """The ruler from ``p`` to ``q`` (world RAS+ mm); ``volume`` names the scan it was measured on."""
    return Distance(p, q, scan=Scan.of(volume), label=label)


def angle(first, vertex, second, volume=None, label: str = "") -> Angle:
    """The angle at ``vertex`` between the rays to ``first`` and ``second`` (world RAS+ mm), in degrees."""
    return Angle(first, vertex, second, scan=Scan.of(volume), label=label)


def point(position, volume=None, label: str = "") -> Point:
    """A point (world RAS+ mm) on ``volume``'s scan."""
    return Point(position, scan=Scan.of(volume), label=label)


def make_sr(items, volume, **options):
    """A DICOM Comprehensive 3D SR of ``items`` made on ``volume``; see :func:`._sr_write.make_sr`."""
    from ._sr_write import make_sr as _make_sr

    return _make_sr(items, volume, **options)


def pick(scene, camera, size, x, y, device: str = "cpu"):
    """The world point of the first visible surface under the picture's point ``(x, y)``; see
    :func:`._pick.pick`."""
    from ._pick import pick as _pick

    return _pick(scene, camera, size, x, y, device=device)
