"""Stenosis and dilation along a vessel: the narrowest and widest sections against the healthy ones either side.

A diameter profile (mm along the arc) is read as a radiologist reads one:

1. **The healthy calibre** along the path: a running median of the equivalent diameter over
   :data:`WINDOW` median diameters of arc (a lesion shorter than half of it does not move it), within
   the segment between two branch points (an iliac artery is not a narrowed aorta), the branch points'
   stretches left out (a plane through a bifurcation holds two lumens).
2. **The stenosis**: the section narrowest against that calibre; its lesion is the stretch round it
   narrower than :data:`HEALTHY` times the calibre; the healthy segments are the :data:`REFERENCE`
   median diameters of arc beyond each end of the lesion whose sections stay within :data:`HEALTHY` of the
   calibre. The reference diameter is the mean of the two segments' means (one alone at an end of the
   path), and the stenosis the diameter reduction ``1 - d_min / d_ref`` in per cent (NASCET's measure
   on equivalent diameters). It is flagged from :data:`STENOSIS_FLAG` per cent.
3. **The maximum**: the section of largest maximum (Feret) diameter, with the same reference; flagged as
   an aneurysm where its equivalent diameter is at least :data:`ANEURYSM_FLAG` times the reference.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Lesion", "find_stenosis", "find_maximum", "healthy_calibre", "WINDOW", "HEALTHY", "REFERENCE",
           "STENOSIS_FLAG", "ANEURYSM_FLAG"]

#: the running median of the healthy calibre spans this many median diameters of arc
WINDOW = 8.0
#: a section within this factor of the healthy calibre (either way) is healthy
HEALTHY = 0.1
#: each healthy reference segment is this many median diameters of arc long
REFERENCE = 2.0
#: a diameter reduction from this many per cent is flagged as a stenosis
STENOSIS_FLAG = 20.0
#: a section this many times wider than its reference is flagged as an aneurysm (a 50 % dilation)
ANEURYSM_FLAG = 1.5


@dataclass(frozen=True)
class Lesion:
    """A stenosis or a maximum: ``index`` of its section, ``arc`` (mm), ``diameter`` (mm: the equivalent
    diameter for a stenosis, the maximum diameter for a maximum), ``reference`` (mm, the mean equivalent
    diameter of the healthy segments either side), ``extent`` (start, end) arc mm of the lesion,
    ``percent`` (diameter reduction for a stenosis, dilation for a maximum), ``flagged``."""

    kind: str
    index: int
    arc: float
    diameter: float
    reference: float
    extent: tuple[float, float]
    percent: float
    flagged: bool

    def to_dict(self) -> dict:
        return {"kind": self.kind, "arc_mm": round(self.arc, 1), "diameter_mm": round(self.diameter, 1),
                "reference_mm": round(self.reference, 1), "extent_mm": [round(e, 1) for e in self.extent],
                "percent": round(self.percent, 1), "flagged": bool(self.flagged)}


def healthy_calibre(arc: np.ndarray, diameter: np.ndarray, exclude: np.ndarray, segment: np.ndarray) -> np.ndarray:
    """The running median of ``diameter`` over :data:`WINDOW` median diameters of ``arc`` within each
    ``segment`` (an id per section), sections in ``exclude`` left out (their neighbours' value)."""
    keep = ~exclude & (diameter > 0)
    if not keep.any():
        return np.full(len(arc), np.nan)
    half = 0.5 * WINDOW * float(np.median(diameter[keep]))
    out = np.empty(len(arc))
    for k, s in enumerate(arc):
        same = keep & (segment == segment[k])
        pool = same if same.any() else keep
        sel = pool & (np.abs(arc - s) <= half)
        out[k] = np.median(diameter[sel]) if sel.any() else diameter[pool][int(np.argmin(np.abs(arc[pool] - s)))]
    return out


def _extent(outside: np.ndarray, k: int) -> tuple[int, int]:
    """The run of True in ``outside`` holding ``k`` (just ``k`` where it is False): first and last index."""
    a = b = k
    while a > 0 and outside[a - 1]:
        a -= 1
    while b < len(outside) - 1 and outside[b + 1]:
        b += 1
    return a, b


def _reference(arc, diameter, healthy, a: int, b: int, length: float) -> float:
    """The mean of the healthy segments' mean diameters beyond ``a`` (before) and ``b`` (after)."""
    before = healthy & (arc < arc[a]) & (arc >= arc[a] - length)
    after = healthy & (arc > arc[b]) & (arc <= arc[b] + length)
    means = [float(np.mean(diameter[m])) for m in (before, after) if m.any()]
    return float(np.mean(means)) if means else float("nan")


def _lesion(kind, arc, diameter, value, calibre, exclude, segment, k, outside) -> tuple:
    a, b = _extent(outside, k)
    healthy = ~exclude & (np.abs(diameter / calibre - 1.0) <= HEALTHY) & (segment == segment[k])
    length = REFERENCE * float(np.median(diameter[diameter > 0]))
    ref = _reference(arc, diameter, healthy, a, b, length)
    return (kind, int(k), float(arc[k]), float(value), ref, (float(arc[a]), float(arc[b])))


def find_stenosis(arc, diameter, exclude, segment) -> Lesion:
    """The narrowest section against the healthy calibre, and its diameter reduction (see the module docstring);
    ``exclude`` (bool per section) are never lesions nor healthy, ``segment`` (an id per section) the stretches
    between branch points."""
    calibre = healthy_calibre(arc, diameter, exclude, segment)
    ratio = np.where(exclude, np.inf, diameter / calibre)
    k = int(np.argmin(ratio))
    args = _lesion("stenosis", arc, diameter, diameter[k], calibre, exclude, segment, k,
                   ~exclude & (diameter < (1.0 - HEALTHY) * calibre))
    percent = 100.0 * (1.0 - args[3] / args[4]) if args[4] > 0 else float("nan")
    return Lesion(*args, percent, bool(percent >= STENOSIS_FLAG))


def find_maximum(arc, diameter, max_diameter, exclude, segment) -> Lesion:
    """The section of largest maximum diameter, and its equivalent diameter's dilation against the healthy
    segments either side (see the module docstring)."""
    calibre = healthy_calibre(arc, diameter, exclude, segment)
    k = int(np.argmax(np.where(exclude, -np.inf, max_diameter)))
    args = _lesion("maximum", arc, diameter, max_diameter[k], calibre, exclude, segment, k,
                   ~exclude & (diameter > (1.0 + HEALTHY) * calibre))
    ratio = diameter[k] / args[4] if args[4] > 0 else float("nan")
    return Lesion(*args, 100.0 * (ratio - 1.0), bool(ratio >= ANEURYSM_FLAG))
