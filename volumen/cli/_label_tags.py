"""Where the structures' names go on a labelled slice (``volumen slices --labels``): inside each structure, never
over another name.

Each name is anchored at the pixel of its structure farthest from the structure's edge (the centre of its largest
inscribed circle: the centroid of a curved or ring-shaped structure can lie outside it). The names are placed
largest structure first; one whose box would meet a box already placed (with :data:`MARGIN` pixels between) or
leave the picture is moved to the structure's next-deepest pixels, and left out where none of
:data:`TRIES` of them has room: an atlas of a hundred regions on one slice names the ones there is room for
instead of a heap of overlapping text.
"""

from __future__ import annotations

import numpy as np

__all__ = ["place_tags", "MARGIN", "TRIES"]

#: pixels kept free between two names' boxes
MARGIN = 4
#: how many of a structure's deepest pixels are tried as its name's centre
TRIES = 12


def _depth_order(mask: np.ndarray) -> np.ndarray:
    """``(row, col)`` of the pixels of ``mask`` from the farthest from its edge, at most :data:`TRIES` of them,
    spread apart (every k-th of the deepest)."""
    from scipy import ndimage

    rows, cols = np.nonzero(mask)
    r0, r1, c0, c1 = rows.min(), rows.max() + 1, cols.min(), cols.max() + 1
    depth = ndimage.distance_transform_edt(np.pad(mask[r0:r1, c0:c1], 1))[1:-1, 1:-1]
    flat = np.argsort(depth, axis=None, kind="stable")[::-1][: max(1, int(mask.sum() // 4))]
    picks = flat[:: max(1, len(flat) // TRIES)][:TRIES]
    rr, cc = np.unravel_index(picks, depth.shape)
    return np.stack([rr + r0, cc + c0], axis=1)


def _meets(box, boxes) -> bool:
    x0, y0, x1, y1 = box
    return any(x0 < b[2] + MARGIN and b[0] < x1 + MARGIN and y0 < b[3] + MARGIN and b[1] < y1 + MARGIN
               for b in boxes)


def place_tags(lab: np.ndarray, values, sizes: dict) -> list[tuple[int, tuple[float, float], tuple]]:
    """``[(value, (x, y) centre, (x0, y0, x1, y1) box)]`` of the names that fit on the label slice ``lab`` (module
    docstring); ``sizes``: value -> (width, height) of its name's text in pixels."""
    height, width = lab.shape[:2]
    areas = {int(v): int(np.count_nonzero(lab == v)) for v in values}
    placed: list = []
    for v in sorted((v for v in areas if areas[v]), key=lambda v: -areas[v]):
        w, h = sizes[v]
        for row, col in _depth_order(lab == v):
            box = (col + 0.5 - w / 2, row + 0.5 - h / 2, col + 0.5 + w / 2, row + 0.5 + h / 2)
            inside = box[0] >= 0 and box[1] >= 0 and box[2] <= width and box[3] <= height
            if inside and not _meets(box, [b for _, _, b in placed]):
                placed.append((v, (col + 0.5, row + 0.5), box))
                break
    return placed
