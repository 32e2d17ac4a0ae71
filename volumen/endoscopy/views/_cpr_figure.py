"""A CPR as a picture: grey values through a window, the cross-sections' positions marked, the sections beside it.

:func:`cpr_figure` lays out, left to right, the CPR (row 0, the path's start,
at the top) and a column of cross-sections (:func:`cross_section`), each with a
coloured frame; the CPR carries a tick of the same colour at both edges and a
dot on the centerline at the section's arc. The CPR and the column are each
enlarged by an integer factor (nearest neighbour) to about ``height`` pixels:
enlarged by the one factor that fitted the taller of them, a short path's CPR
(VMTK's aorta into an iliac artery: 87 rows beside four sections' 204) filled
under half the figure's height above a black band.
"""

from __future__ import annotations

import numpy as np

from ._cpr import CPR, cross_section

__all__ = ["cpr_figure", "window_grey", "vessel_window", "MARK_COLORS", "WALL_RADII", "WINDOW_MARGIN"]

MARK_COLORS = np.array([(255, 200, 0), (0, 200, 255), (255, 80, 200), (120, 255, 80), (255, 120, 40),
                        (160, 140, 255)], np.uint8)
#: the tissue round the lumen is read this many median radii from the centerline
WALL_RADII = (1.5, 3.0)
#: the vessel's window reaches this many times the lumen-to-tissue difference past each of them
WINDOW_MARGIN = 0.5


def window_grey(values: np.ndarray, window: tuple[float, float] | None = None) -> np.ndarray:
    """``(H, W, 3)`` uint8: ``values`` from ``window = (lo, hi)`` (data units; default the 1st and 99.5th
    percentiles) to black..white; NaN (outside the scan) black."""
    v = np.asarray(values, float)
    finite = v[np.isfinite(v)]
    if window is None:
        window = tuple(np.percentile(finite, [1.0, 99.5])) if finite.size else (0.0, 1.0)
    lo, hi = float(window[0]), float(window[1])
    g = np.clip((np.nan_to_num(v, nan=lo) - lo) / max(hi - lo, 1e-12), 0.0, 1.0)
    return np.repeat((255 * g + 0.5).astype(np.uint8)[..., None], 3, axis=2)


def vessel_window(cpr: CPR, radius: float) -> tuple[float, float] | None:
    """``(lo, hi)``: the window that shows the lumen against the tissue round it, as a vascular window does: the
    lumen's median value (the centerline's column) and the tissue's (:data:`WALL_RADII` median radii ``radius``
    (mm) from it, both sides), the darker a quarter and the brighter three quarters up the ramp
    (:data:`WINDOW_MARGIN`), within the CPR's
    1st percentile and maximum (air stays black beside an air lumen, a contrast lumen is not cut). None where
    the path has no radius or the two are not told apart.

    Spanned over the CPR's 1st..99.5th percentiles, a CT's ran from the lung's air to the spine's bone, and the
    contrast-filled aorta stood a flat grey on grey tissue."""
    values = np.asarray(cpr.values, float)
    if not radius > 0 or not np.isfinite(values).any():
        return None
    offset = np.arange(values.shape[1])[None, :] - cpr.centre[:, None]
    near = np.abs(offset) * cpr.pixel
    lumen = np.nanmedian(np.where(near <= 0.5 * radius, values, np.nan))
    ring = (near >= WALL_RADII[0] * radius) & (near <= WALL_RADII[1] * radius)
    tissue = np.nanmedian(np.where(ring, values, np.nan)) if ring.any() else np.nan
    finite = values[np.isfinite(values)]
    step = abs(lumen - tissue)
    if not step > 0:
        return None
    lo = max(min(lumen, tissue) - WINDOW_MARGIN * step, float(np.percentile(finite, 1.0)))
    hi = min(max(lumen, tissue) + WINDOW_MARGIN * step, float(finite.max()))
    return (lo, hi) if hi > lo else None


def _frame(tile: np.ndarray, color) -> np.ndarray:
    out = np.empty((tile.shape[0] + 4, tile.shape[1] + 4, 3), np.uint8)
    out[:] = color
    out[2:-2, 2:-2] = tile
    return out


def cpr_figure(volume, centerline, cpr: CPR, marks=(), *, window=None, section_width: float = 40.0,
               height: int = 600) -> np.ndarray:
    """``(H, W, 3)`` uint8: the CPR with the cross-sections at arcs ``marks`` (mm) marked and shown beside it,
    through ``window = (lo, hi)`` (data units; None: :func:`vessel_window`, else the CPR's 1st..99.5th
    percentiles)."""
    if window is None:
        window = vessel_window(cpr, float(np.median(centerline.radius)) if len(centerline.radius) else 0.0)
    if window is None:
        finite = cpr.values[np.isfinite(cpr.values)]
        window = tuple(np.percentile(finite, [1.0, 99.5]))
    img = window_grey(cpr.values, window)
    tiles = []
    for n, s in enumerate(marks):
        color = MARK_COLORS[n % len(MARK_COLORS)]
        r = cpr.row_at(s)
        img[r, :3] = color
        img[r, -3:] = color
        c = int(round(cpr.centre[r]))
        img[r, max(c - 1, 0):c + 2] = color
        tiles.append(_frame(window_grey(cross_section(volume, centerline, s, width=section_width, pixel=cpr.pixel),
                                        window), color))
    img = _enlarged(img, height)
    if not tiles:
        return img
    col_w = max(t.shape[1] for t in tiles)
    column = np.zeros((sum(t.shape[0] for t in tiles), col_w, 3), np.uint8)
    y = 0
    for t in tiles:
        column[y:y + t.shape[0], :t.shape[1]] = t
        y += t.shape[0]
    column = _enlarged(column, height)
    fig = np.zeros((max(img.shape[0], column.shape[0]), img.shape[1] + 4 + column.shape[1], 3), np.uint8)
    fig[:img.shape[0], :img.shape[1]] = img
    fig[:column.shape[0], img.shape[1] + 4:] = column
    return fig


def _enlarged(picture: np.ndarray, height: int) -> np.ndarray:
    """``picture`` enlarged by the integer factor (at least 1, nearest neighbour) that brings it nearest ``height``
    rows."""
    k = max(1, int(round(height / picture.shape[0])))
    return np.repeat(np.repeat(picture, k, axis=0), k, axis=1)
