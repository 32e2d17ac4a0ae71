"""Linked axial, coronal and sagittal views with a window/level for the notebook.

The three views share one crosshair, a voxel ``(i, j, k)`` of the canonical (RAS-ordered) volume
(:func:`volumen.core.canonical`): each view's slider moves its own plane, and every view draws where
the two other planes cut it (axial: red line = coronal plane, green = sagittal...). Display follows
:func:`volumen.core.slice_at`: axial rows run anterior to posterior and columns right to left, coronal
and sagittal rows superior to inferior.
"""

from __future__ import annotations

import ipywidgets as widgets
import numpy as np

from ..core import PLANES, Window, canonical, default_window, slice_image, table_range
from . import pictures

__all__ = ["SliceViews", "slice_picture", "crosshair_pixels", "PLANE_AXIS", "PLANE_COLOURS"]

#: voxel axis (0 i, 1 j, 2 k) each plane's slider moves
PLANE_AXIS = {"axial": 2, "coronal": 1, "sagittal": 0}
#: line colour of each plane where the other views show it
PLANE_COLOURS = {"axial": (60, 120, 255), "coronal": (230, 60, 60), "sagittal": (60, 200, 60)}


def crosshair_pixels(shape_ijk, plane: str, ijk) -> dict[str, tuple[str, int]]:
    """Where the two other planes cut ``plane``'s display slice: ``{other: ("row" | "col", index)}``."""
    ni, nj, nk = shape_ijk
    i, j, k = ijk
    if plane == "axial":      # rows A->P (j reversed), columns R->L (i reversed)
        return {"coronal": ("row", nj - 1 - j), "sagittal": ("col", ni - 1 - i)}
    if plane == "coronal":    # rows S->I, columns R->L
        return {"axial": ("row", nk - 1 - k), "sagittal": ("col", ni - 1 - i)}
    return {"axial": ("row", nk - 1 - k), "coronal": ("col", nj - 1 - j)}  # sagittal: rows S->I, columns A->P


def slice_picture(can, plane: str, ijk, window: Window) -> np.ndarray:
    """uint8 (rows, cols, 3): the windowed slice of the canonical volume ``can`` through ``ijk`` with the crosshair."""
    index = int(ijk[PLANE_AXIS[plane]])
    gray = slice_image(can, plane, index=index, window=window, square_pixels=False, canonical_volume=can)
    rgb = np.repeat(gray[..., None], 3, axis=2) if gray.ndim == 2 else gray.copy()
    for other, (kind, at) in crosshair_pixels(can.shape[::-1], plane, ijk).items():
        if kind == "row":
            rgb[at, :] = PLANE_COLOURS[other]
        else:
            rgb[:, at] = PLANE_COLOURS[other]
    return rgb


class SliceViews:
    """Three linked slice views of ``volume`` with window and level sliders; ``box`` is the widget."""

    def __init__(self, volume, width: int = 220):
        self.volume = canonical(volume)
        lo, hi = table_range(self.volume)  # not out to a fill or far outliers
        start = default_window(volume)  # soft tissue for a CT, the display range otherwise
        level, wwidth = min(max(start.level, lo), hi), start.width
        span = max(hi - lo, 1e-6)
        self.level = widgets.FloatSlider(value=level, min=lo, max=hi, step=span / 500, description="level",
                                         continuous_update=True)
        self.width = widgets.FloatSlider(value=min(wwidth, 2 * span), min=span / 500, max=2 * span,
                                         step=span / 500, description="window")
        ni, nj, nk = self.volume.shape[::-1]
        self.ijk = [ni // 2, nj // 2, nk // 2]
        self.sliders, self.images = {}, {}
        sp = self.volume.spacing[::-1]  # (di, dj, dk) mm
        for plane in PLANES:
            ax = PLANE_AXIS[plane]
            n = (ni, nj, nk)[ax]
            self.sliders[plane] = widgets.IntSlider(value=self.ijk[ax], min=0, max=n - 1, description=plane)
            self.sliders[plane].observe(lambda ch, a=ax: self._move(a, ch["new"]), names="value")
            cols, rows = [(ni, nj), (ni, nk), (nj, nk)][PLANES.index(plane)]
            csp, rsp = [(sp[0], sp[1]), (sp[0], sp[2]), (sp[1], sp[2])][PLANES.index(plane)]
            h = int(round(width * rows * rsp / (cols * csp)))  # square millimetres on screen
            self.images[plane] = widgets.Image(format="png", layout=widgets.Layout(width=f"{width}px",
                                                                                    height=f"{h}px"))
        for s in (self.level, self.width):
            s.observe(lambda _ch: self.refresh(), names="value")
        self.refresh()
        self.box = widgets.VBox([
            widgets.HBox([widgets.VBox([self.images[p], self.sliders[p]]) for p in PLANES]),
            widgets.HBox([self.level, self.width]),
        ])

    @property
    def window(self) -> Window:
        return Window(level=self.level.value, width=self.width.value)

    def _move(self, axis: int, index: int) -> None:
        self.ijk[axis] = int(index)
        self.refresh()

    def picture(self, plane: str) -> np.ndarray:
        """The current uint8 (rows, cols, 3) picture of ``plane``."""
        return slice_picture(self.volume, plane, self.ijk, self.window)

    def refresh(self) -> None:
        """Redraw the three views (after a slider or window change)."""
        for plane in PLANES:
            self.images[plane].value = pictures.png_bytes(self.picture(plane))
