"""From two points (and perhaps a segmentation) to the lumen's wall and a checked centerline.

What ``volumen fly`` and the application's endoscopy panel do alike:

* :func:`lumen_wall` -- the lumen and the wall to draw: grown from the start point with
  the estimate made there (:func:`~volumen.endoscopy.find_lumen`), and from the end point
  too when there is one and no range or threshold is given, the larger of the two kept
  when they agree, the smaller when one leaked
  (:func:`~volumen.endoscopy.lumen._two_ends.lumen_between`), or given as a mask,
  whose boundary values give the estimate (:func:`estimate_from_mask`); ``--range`` and
  ``--threshold`` override either;
* :func:`make_flight` -- the :class:`~volumen.endoscopy.Flight` along a centerline: keyframes
  every ``every`` mm aimed down the lumen (:func:`~volumen.endoscopy.aim_keyframes`), the
  wall drawn as an isosurface of the lumen's field at the estimate's threshold, lit by a
  flashlight that falls off beyond :data:`FALLOFF` times the lumen's median radius;
* :func:`checked_centerline` -- the centerline between the points
  (:func:`~volumen.endoscopy.compute_centerline`), refused as a leak when it is both
  more than twice as long as the straight line between its ends and runs through a
  region more than twice as wide as the lumen at either end. Either alone is anatomy
  (a tortuous colon; the trachea between two small bronchi); both together is the
  detour of a path through a region the lumen leaked into.
"""

from __future__ import annotations

import numpy as np

from ...errors import LumenError

__all__ = ["lumen_wall", "checked_centerline", "make_flight", "DETOUR", "WIDENING"]

#: a path longer than this times the straight distance between its ends is a detour ...
DETOUR = 2.0
#: ... and, through a region wider than this times the lumen at either end, a leak
WIDENING = 2.0
#: the flythrough's flashlight reaches this times the lumen's median radius before it falls off
#: (:attr:`~volumen.endoscopy.Endoscope.falloff`): the lumen ahead dark, the near wall bright
FALLOFF = 3.0


def lumen_wall(volume, start, end=None, *, kind: str = "auto", value_range=None, threshold=None, mask=None):
    """The :class:`~volumen.endoscopy.LumenWall` of the lumen holding ``start`` (and ``end``), world mm.

    ``mask`` (bool ``[z, y, x]`` on the volume's grid): the lumen as given, its estimate from its boundary
    values; None: grown from ``start`` (:func:`~volumen.endoscopy.find_lumen`), and from ``end`` too when
    neither ``value_range`` nor ``threshold`` is given (:func:`~volumen.endoscopy.lumen._two_ends.lumen_between`: the
    wall's ``note`` says when the two disagreed). ``value_range`` (lo, hi) and ``threshold`` (data units)
    override the estimate.

    Raises
    ------
    LumenError
        As :func:`~volumen.endoscopy.find_lumen` does (points, no lumen, leaks).
    """
    from ..lumen._drawn_wall import LumenWall
    from ..lumen._find import find_lumen
    from ..lumen._mask_estimate import estimate_from_mask
    from ..lumen._two_ends import lumen_between

    if mask is None and end is not None and value_range is None and threshold is None:
        lumen, est, note = lumen_between(volume, start, end, kind=kind)
        return LumenWall(lumen, est, note=note)
    if mask is None:
        lumen, est = find_lumen(volume, start, end, kind=kind, value_range=value_range, threshold=threshold)
        return LumenWall(lumen, est)
    wall = estimate_from_mask(volume, mask, kind)
    est = wall.estimate
    if threshold is not None:
        est = est.with_threshold(threshold)
    if value_range is not None:
        est = est.with_range(value_range)
    return LumenWall(wall.mask, est, wall.shape_only and threshold is None)


def _end_radius(cl, at_start: bool, reach: float = 5.0) -> float:
    """The lumen's radius at one end of the centerline: the median over its first (last) ``reach`` mm."""
    s = cl.arc if at_start else cl.length - cl.arc
    return float(np.median(cl.radius[s <= reach]))


def checked_centerline(volume, lumen, start, end):
    """The centerline of ``lumen`` (bool mask) from ``start`` to ``end`` (world mm), refused as a leak by a
    :class:`LumenError` naming where when it detours through a widening (see the module docstring)."""
    from ..lumen._find import FLAGS, _fmt
    from ..path._centerline import compute_centerline

    cl = compute_centerline(volume, lumen, start, end)
    straight = float(np.linalg.norm(cl.points[-1] - cl.points[0]))
    ends = max(_end_radius(cl, True), _end_radius(cl, False), 0.5 * float(min(volume.spacing)))
    k = int(np.argmax(cl.radius))
    if cl.length > DETOUR * max(straight, 1e-9) and cl.radius[k] > WIDENING * ends:
        raise LumenError(f"the lumen leaks: the path between the points runs {cl.length:.0f} mm for "
                         f"{straight:.0f} mm in a straight line, through a region {2 * cl.radius[k]:.0f} mm wide at "
                         f"{_fmt(cl.points[k])}, though the lumen is {2 * ends:.0f} mm wide at its ends; {FLAGS}")
    return cl


def make_flight(volume, wall, centerline, *, every: float = 10.0, speed: float = 20.0, **endoscope):
    """The :class:`~volumen.endoscopy.Flight` along ``centerline`` through the lumen of ``wall`` (a
    :class:`~volumen.endoscopy.LumenWall`) on ``volume``: keyframes every ``every`` mm, played at ``speed``
    mm/s, each aimed at the farthest centerline point it sees; the endoscope draws ``wall``'s field
    (isosurface at the estimate's threshold, its transfer function for composite mode, the flashlight's
    ``falloff`` three times the centerline's median radius), ``endoscope`` overriding its settings
    (``mode``, ``shading``, ``fov``...)."""
    from ..path._aim import aim_keyframes
    from ..path._keyframes import KeyframePath
    from ._endoscope import Endoscope
    from ._saved import Flight

    path = aim_keyframes(KeyframePath.from_centerline(centerline, every=every, speed=speed), centerline, volume,
                         wall.mask)
    est = wall.estimate
    settings = {"mode": "isosurface", "threshold": est.threshold, "transfer": est.transfer(),
                "falloff": FALLOFF * float(np.median(centerline.radius)), **endoscope}
    return Flight(path, Endoscope(volume=wall.volume(volume), **settings), centerline, wall)
