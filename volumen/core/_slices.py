"""Axial, coronal and sagittal slices in radiological display orientation, and windowing.

Display conventions (as on a radiology workstation):

* axial: seen from the feet, patient's Right on the image's left, Anterior at the top;
* coronal: seen from the front, patient's Right on the image's left, Superior at the top;
* sagittal: seen from the patient's left, Anterior on the image's left, Superior at the top.

Slices are cut from the volume reoriented to the nearest canonical (RAS) voxel
order by permuting and flipping axes only (no interpolation), so an oblique
volume shows its slices along its own voxel axes, labelled by the nearest
anatomical plane.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from ..errors import ModalityError, OutsideVolumeError, UnknownChoiceError
from ._ct import hu_offset
from ._display import LABEL_VALUES, display_range
from ._subject import subject_values
from ._values import strided_values
from ._volume import Volume, axis_codes, is_chunked

__all__ = ["Window", "WINDOW_PRESETS", "PLANES", "canonical", "default_window", "montage", "named_window", "slice_at",
           "slice_image", "window_to_uint8"]

Plane = Literal["axial", "coronal", "sagittal"]
PLANES: tuple[str, ...] = ("axial", "coronal", "sagittal")


@dataclass(frozen=True)
class Window:
    """A display window: values ``level - width/2 .. level + width/2`` map to black .. white.

    ``level`` and ``width`` are in the data's units (HU for CT).
    """

    level: float
    width: float

    def __post_init__(self):
        if not (np.isfinite(self.level) and np.isfinite(self.width) and self.width > 0):
            raise ValueError(f"a window needs a finite level and a finite positive width, got level {self.level}, "
                             f"width {self.width}")

    @property
    def range(self) -> tuple[float, float]:
        return self.level - self.width / 2, self.level + self.width / 2


#: the percentiles of a scan's subject values (not a CT's) its first slice window spans (:func:`default_window`)
SLICE_PERCENTILES = (1.0, 99.5)
#: CT window presets in HU (level, width), as commonly used in radiology.
WINDOW_PRESETS: dict[str, Window] = {
    "bone": Window(level=400.0, width=1800.0),
    "soft-tissue": Window(level=40.0, width=400.0),
    "lung": Window(level=-600.0, width=1500.0),
    "brain": Window(level=40.0, width=80.0),
}


def named_window(name: str, volume: Volume | None = None) -> Window:
    """The CT window ``name`` of :data:`WINDOW_PRESETS` (HU) for ``volume``: moved onto a CT's stored values
    (:func:`hu_offset`).

    Raises
    ------
    volumen.errors.UnknownChoiceError
        ``name`` is not a window name (the message lists them and the closest).
    volumen.errors.ModalityError
        ``volume`` is not a CT (:func:`is_ct`): a window in HU would saturate it; the message gives the level and
        width of its own display range.
    """
    if name not in WINDOW_PRESETS:
        raise UnknownChoiceError("window", name, WINDOW_PRESETS)
    window = WINDOW_PRESETS[name]
    if volume is None:
        return window
    offset = hu_offset(volume)
    if offset is None:
        own = default_window(volume)
        kind = f"modality {volume.modality}" if volume.modality else "no modality"
        raise ModalityError(f"window {name!r} is a CT window in HU (level {window.level:g}, width {window.width:g}) "
                            f"and this scan is not a CT ({kind}, {_named(volume)}): give LEVEL,WIDTH in its units "
                            f"(its display range is level {own.level:.4g}, width {own.width:.4g})")
    return Window(level=window.level + offset, width=window.width)


def default_window(volume: Volume) -> Window:
    """The window a volume is first shown with: ``soft-tissue`` (L 40, W 400 HU) for a CT (:func:`is_ct`,
    also one read without a modality; on its stored values: ``hu_offset``), else its display range (its value
    range, less far outliers: ``_display``) narrowed to the subject's values (``subject_values``) from their
    :data:`SLICE_PERCENTILES` first to last: a skull-stripped brain or a template lies far above its background,
    and windowed from the background its darkest tissue was mid-grey (milky); the few brightest voxels (fat,
    inflow) saturate. Not for a label map (its values are names, not tissue)."""
    offset = hu_offset(volume)
    if offset is not None:
        w = WINDOW_PRESETS["soft-tissue"]
        return Window(level=w.level + offset, width=w.width)
    lo, hi = display_range(volume)
    inside = np.empty(0) if _few_values(volume) else subject_values(volume)
    inside = inside[np.isfinite(inside)] if inside.size else inside
    if inside.size:
        bottom, top = (float(v) for v in np.percentile(inside, SLICE_PERCENTILES))
        lo, hi = (bottom, top) if lo <= bottom < top <= hi else (lo, hi)
    return Window(level=(lo + hi) / 2, width=max(hi - lo, 1e-6))


def _few_values(volume) -> bool:
    """A label map or a colour volume: integers of at most ``LABEL_VALUES`` distinct values in the sample."""
    s = strided_values(volume)
    return bool(volume.is_color) or (np.issubdtype(s.dtype, np.integer) and np.unique(s).size <= LABEL_VALUES)


def window_to_uint8(values: np.ndarray, window: Window | str | tuple[float, float] | None = None) -> np.ndarray:
    """Map values to 8-bit gray through a window.

    Parameters
    ----------
    values : array
        Data in physical units.
    window : Window, preset name, ``(level, width)`` or None
        ``None`` uses the 1st..99th percentile of ``values``.

    Returns
    -------
    uint8 array of the same shape: ``round(255 * clip((v - lo) / (hi - lo), 0, 1))``.
    """
    if window is None:
        finite = values[np.isfinite(values)] if np.issubdtype(values.dtype, np.floating) else values
        lo, hi = (np.percentile(finite, [1, 99]) if finite.size else (0.0, 1.0))
        if not hi > lo:
            hi = lo + 1.0
        window = Window(level=(lo + hi) / 2, width=hi - lo)
    elif isinstance(window, str):
        if window not in WINDOW_PRESETS:
            raise UnknownChoiceError("window", window, WINDOW_PRESETS)
        window = WINDOW_PRESETS[window]
    elif not isinstance(window, Window):
        window = Window(*window)
    lo, hi = window.range
    x = (np.asarray(values, dtype=np.float32) - np.float32(lo)) / np.float32(hi - lo)
    return np.rint(np.clip(np.nan_to_num(x, nan=0.0), 0.0, 1.0) * 255.0).astype(np.uint8)


def canonical(volume: Volume) -> Volume:
    """The same volume with voxel axes permuted/flipped to the nearest RAS order.

    Afterwards voxel axis i points (mostly) Right, j Anterior, k Superior, and
    ``data[k, j, i]`` is still the sample at ``affine @ (i, j, k, 1)``. Returns
    ``volume`` itself when it is already canonical (no copy).
    """
    codes = axis_codes(volume.affine)
    if codes == "RAS":
        return volume
    target = "RAS"
    opposite = {"L": "R", "P": "A", "I": "S", "R": "R", "A": "A", "S": "S"}
    # for each RAS axis w, which voxel axis (0=i,1=j,2=k) carries it, and flipped?
    src_axis = [next(a for a in range(3) if opposite[codes[a]] == target[w]) for w in range(3)]
    flip = [codes[src_axis[w]] != target[w] for w in range(3)]
    n_ijk = np.array(volume.shape[::-1])
    # new index n_w -> old index along src_axis[w]: flipped ? (N-1-n) : n
    M = np.zeros((4, 4))
    M[3, 3] = 1
    for w in range(3):
        a = src_axis[w]
        M[a, w] = -1.0 if flip[w] else 1.0
        M[a, 3] = n_ijk[a] - 1 if flip[w] else 0.0
    affine = volume.affine @ M
    # data [k, j, i]: numpy axis of voxel axis a is 2 - a
    axes = [2 - src_axis[2 - ax] for ax in range(3)] + ([3] if volume.is_color else [])
    data = np.transpose(volume.data, axes)
    slicer = tuple(slice(None, None, -1) if flip[2 - ax] else slice(None) for ax in range(3))
    data = data[slicer] if is_chunked(data) else np.ascontiguousarray(data[slicer])  # chunked: a lazy view
    spacing = tuple(float(np.linalg.norm(affine[:3, a])) for a in (2, 1, 0))
    return Volume(data, spacing=spacing, affine=affine, modality=volume.modality, units=volume.units,
                  name=volume.name, meta=dict(volume.meta))


def _plane_axis(plane: str) -> int:
    """numpy axis of the canonical volume that a plane cuts: axial k (0), coronal j (1), sagittal i (2)."""
    try:
        return {"axial": 0, "coronal": 1, "sagittal": 2}[plane]
    except KeyError:
        raise UnknownChoiceError("plane", plane, PLANES) from None


def _named(volume: Volume) -> str:
    """How a message names the volume: its file, else its name."""
    return str(volume.meta.get("source") or volume.name or "the volume")


def _outside_error(volume: Volume, world) -> OutsideVolumeError:
    """The error for a world point (RAS+ mm) outside ``volume``: the point, the volume's extent, its file."""
    lo, hi = volume.bounds()
    span = ", ".join(f"{a} {lo[i]:.1f}..{hi[i]:.1f}" for i, a in enumerate("xyz"))
    point = ", ".join(f"{v:g}" for v in np.asarray(world, float))
    return OutsideVolumeError(f"point ({point}) mm (RAS) is outside {_named(volume)}, which spans {span} mm")


def slice_at(volume: Volume, plane: Plane, index: int | None = None, world: tuple[float, float, float] | None = None,
             *, canonical_volume: Volume | None = None) -> tuple[np.ndarray, tuple[float, float]]:
    """Cut one slice for display.

    Parameters
    ----------
    volume : Volume
    plane : {"axial", "coronal", "sagittal"}
    index : int, optional
        Slice index along the plane's normal in the canonical (RAS-ordered) volume:
        axial counts from inferior, coronal from posterior, sagittal from the
        patient's left. Default: the middle slice.
    world : (3,) float, optional
        A world RAS+ mm point; the slice through its nearest voxel is cut.

    Raises
    ------
    volumen.errors.OutsideVolumeError
        The slice (or the point's) is outside the volume; the message gives the point in mm, the volume's extent
        and its file.
    canonical_volume : Volume, optional
        ``canonical(volume)`` when the caller already has it (avoids recomputing).

    Returns
    -------
    image : (rows, cols) or, for a colour volume, (rows, cols, 3) array
        Values in the data's units, row 0 at the top of the display.
    pixel_spacing : (row_mm, col_mm)
        Physical size of a display pixel, for aspect-correct display.
    """
    if index is not None and world is not None:
        raise ValueError("give index or world, not both")
    can = canonical_volume if canonical_volume is not None else canonical(volume)
    ax = _plane_axis(plane)
    n = can.shape[ax]
    if world is not None:
        ijk = can.world_to_index(np.asarray(world, float))
        index = int(np.rint(ijk[2 - ax]))
    if index is None:
        index = n // 2
    if not 0 <= index < n:
        if world is not None:
            raise _outside_error(volume, world)
        raise OutsideVolumeError(f"{plane} slice {index} is outside 0..{n - 1} of {_named(volume)}")
    dz, dy, dx = can.spacing
    if ax == 0:  # axial: rows A (top) -> P, columns R (left) -> L
        img, sp = can.data[index, ::-1, ::-1], (dy, dx)
    elif ax == 1:  # coronal: rows S -> I, columns R -> L
        img, sp = can.data[::-1, index, ::-1], (dz, dx)
    else:  # sagittal: rows S -> I, columns A (left) -> P
        img, sp = can.data[::-1, ::-1, index], (dz, dy)
    return np.ascontiguousarray(img), (float(sp[0]), float(sp[1]))


def slice_image(volume: Volume, plane: Plane, index: int | None = None, world=None,
                window: Window | str | tuple[float, float] | None = None, square_pixels: bool = True,
                canonical_volume: Volume | None = None) -> np.ndarray:
    """An 8-bit display slice: :func:`slice_at`, windowed, resampled to square pixels.

    With ``square_pixels`` the image is stretched (linear interpolation) along the
    axis with the larger pixel spacing so one pixel covers the same mm both ways.
    Returns a uint8 ``(rows, cols)`` array, row 0 at the top; a colour volume gives
    ``(rows, cols, 3)`` RGB, its three channels through one window (8-bit colour
    data with no window is shown as stored, 0..255). A window name is a CT window (:func:`named_window`: on a CT's
    stored values; refused for another modality). With no window the volume's first window
    (:func:`default_window`: ``soft-tissue`` for a CT, else the display range from the subject's darkest tissue, as
    the application's and the page's slice views open), the same in every slice; 8-bit colour as stored, other
    colour the slice's 1st..99th percentile. A volume whose
    ``meta["display_inverted"]`` is true (DICOM MONOCHROME1) is shown inverted.
    """
    img, (sr, sc) = slice_at(volume, plane, index=index, world=world, canonical_volume=canonical_volume)
    if isinstance(window, str):
        window = named_window(window, volume)
    if window is None and not volume.is_color:
        window = default_window(volume)  # a CT's soft tissue, the display range from the subject's darkest tissue
    if window is None and img.dtype == np.uint8:
        window = Window(level=127.5, width=255.0)
    out = window_to_uint8(img, window)
    if volume.meta.get("display_inverted"):  # MONOCHROME1: low values are white
        out = 255 - out
    if square_pixels and not np.isclose(sr, sc, rtol=1e-3):
        from scipy import ndimage

        base = min(sr, sc)
        zoom = (sr / base, sc / base) + ((1.0,) if out.ndim == 3 else ())
        out = ndimage.zoom(out.astype(np.float32), zoom, order=1, mode="nearest")
        out = np.rint(np.clip(out, 0, 255)).astype(np.uint8)
    return out


def montage(volume: Volume, window: Window | str | tuple[float, float] | None = None, world=None,
            gap: int = 4) -> np.ndarray:
    """Axial, coronal and sagittal display slices side by side, as one uint8 image.

    The three planes pass through ``world`` (RAS+ mm; default the volume's
    centre), each with square pixels, bottom-aligned on a black canvas with
    ``gap`` pixels between them. Returns a uint8 ``(rows, cols)`` array, or
    ``(rows, cols, 3)`` for a colour volume.
    """
    can = canonical(volume)
    if world is None:
        world = volume.center
    tiles = [slice_image(volume, p, world=world, window=window, canonical_volume=can) for p in PLANES]
    rows = max(t.shape[0] for t in tiles)
    cols = sum(t.shape[1] for t in tiles) + gap * (len(tiles) - 1)
    out = np.zeros((rows, cols) + tiles[0].shape[2:], np.uint8)
    c = 0
    for t in tiles:
        out[rows - t.shape[0]:, c:c + t.shape[1]] = t
        c += t.shape[1] + gap
    return out
