"""The lumen between two points grown from each end: a lumen that leaks one way only is caught.

Grown from one point, a lumen can break through a thin wall into a neighbouring
structure whose values the estimate made at that point admits (an unopacified jet
in a contrast aorta estimates a low wall threshold that a neighbouring contrast
vessel crosses), while the estimate made at the other point holds the wall. So
:func:`lumen_between` grows the lumen from the start (to the end) and from the end
(to the start) with :func:`~volumen.endoscopy.find_lumen` and compares the two by
``max(|A|, |B|) / |A & B|``, the larger lumen's size over their overlap:

* within :data:`AGREE`, the two ends see the same lumen and differ only in how far
  into its partial-volume edge and its small branches each grew: the larger, the
  more complete, is kept;
* above it, one end's lumen holds a region the other's does not (a leak): the
  smaller, which lacks the other's excess, is kept, with a one-line note of what
  was done and the flags that override it.

Either way the choice depends on the two lumens only, not on which point is the start.

When the end's growth is refused the start's lumen is kept (the end's own
neighbourhood gives no estimate that holds, the start's does); when the start's is
refused its error stands. Only lumens estimated from the points take part: a
range, a threshold or a mask given by the caller is used as given.
"""

from __future__ import annotations

import numpy as np

from ...errors import LumenError
from ._find import FLAGS, _fmt, find_lumen

__all__ = ["lumen_between", "disagreement", "AGREE"]

#: the most ``max(|A|, |B|) / |A & B|`` of the lumens grown from either end that is one lumen seen from
#: both. Measured on ends that see one lumen: 1.00-1.07 on the ten pairs of ``layered_aorta``'s landmarks,
#: 1.06 on ``arch``, 1.12 on ``airways`` (trachea to a small bronchus, whose estimate stops short of the
#: partial-volume edge); on a lumen that swallowed the neighbouring vessel through a thin wall, 1.73. 1.3
#: lies between the largest agreeing value and the leak (their geometric mean is 1.39).
AGREE = 1.3


def disagreement(a: np.ndarray, b: np.ndarray) -> float:
    """``max(|a|, |b|) / |a & b|`` of two masks (1: the same; inf: disjoint)."""
    overlap = int(np.count_nonzero(a & b))
    larger = max(int(np.count_nonzero(a)), int(np.count_nonzero(b)))
    return float(larger / overlap) if overlap else float("inf")


def lumen_between(volume, start, end, *, kind: str = "auto"):
    """The lumen holding ``start`` and ``end`` (world mm), grown from both (see the module docstring).

    Returns
    -------
    mask : (nz, ny, nx) bool
    estimate : LumenEstimate
        The kept lumen's.
    note : str
        One line when the two ends disagreed (what was kept, the flags that override), else ``""``.

    Raises
    ------
    LumenError
        As :func:`~volumen.endoscopy.find_lumen` from the start raises.
    """
    forward = find_lumen(volume, start, end, kind=kind)
    try:
        backward = find_lumen(volume, end, start, kind=kind)
    except LumenError:
        return (*forward, "")
    ratio = disagreement(forward[0], backward[0])
    sizes = [int(np.count_nonzero(forward[0])), int(np.count_nonzero(backward[0]))]
    if ratio <= AGREE:
        return (*(forward if sizes[0] >= sizes[1] else backward), "")
    kept, other = (forward, backward) if sizes[0] <= sizes[1] else (backward, forward)
    side = "start" if kept is forward else "end"
    point = start if kept is forward else end
    ml = float(np.prod(volume.spacing)) / 1000.0
    excess = int(np.count_nonzero(other[0] & ~kept[0])) * ml
    note = (f"the lumen grown from each end differs ({ratio:.2f} times their overlap): the other end's "
            f"holds {excess:.3g} ml more, a leak through its wall; kept the {side} point's {_fmt(point)}, "
            f"{min(sizes) * ml:.3g} ml; {FLAGS}")
    return (*kept, note)
