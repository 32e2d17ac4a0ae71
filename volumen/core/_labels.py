"""A label map: integer structure ids on a voxel grid, with a name and a colour for each.

:class:`LabelMap` is what :func:`volumen.load_labels` returns for every kind of
segmentation file (a NIfTI/NRRD label map with a names table, a Slicer
``.seg.nrrd``, a DICOM SEG, a folder of one mask per structure). 0 is background.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import choice_message

__all__ = ["LabelMap", "LabelLayer", "default_color"]

# a qualitative palette (linear RGB, 0..1) for structures whose file gives no colour
_PALETTE = np.array([
    [0.90, 0.30, 0.25], [0.25, 0.55, 0.90], [0.35, 0.80, 0.35], [0.95, 0.75, 0.20], [0.70, 0.40, 0.85],
    [0.20, 0.80, 0.80], [0.95, 0.50, 0.70], [0.60, 0.45, 0.30], [0.55, 0.75, 0.95], [0.85, 0.85, 0.45],
    [0.45, 0.30, 0.70], [0.95, 0.60, 0.35],
])


def default_color(value: int) -> tuple[float, float, float]:
    """A distinct colour (linear RGB 0..1) for label ``value`` when its file names none."""
    return tuple(float(c) for c in _PALETTE[(int(value) - 1) % len(_PALETTE)])


@dataclass(eq=False)
class LabelMap:
    """Structures of a segmentation on a voxel grid.

    Parameters
    ----------
    data : (nz, ny, nx) unsigned int array
        Label value per voxel ``[z, y, x]``; 0 is background.
    spacing : (3,) float, mm
        ``(dz, dy, dx)``.
    affine : (4, 4) float
        Voxel ``(i, j, k, 1)`` -> world RAS+ mm (as :class:`~volumen.core.Volume`).
    names : dict int -> str
        Structure name per label value (every value present has one).
    colors : dict int -> (3,) float
        Linear RGB 0..1 per label value.
    meta : dict
        ``source`` (path), ``warnings`` (list of str), format details.
    """

    data: np.ndarray
    spacing: tuple[float, float, float] = (1.0, 1.0, 1.0)
    affine: np.ndarray | None = None
    names: dict[int, str] = field(default_factory=dict)
    colors: dict[int, tuple[float, float, float]] = field(default_factory=dict)
    meta: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        data = np.asarray(self.data)
        if data.ndim != 3:
            raise ValueError(f"a label map is 3-D [z, y, x], got shape {data.shape}")
        if not (np.issubdtype(data.dtype, np.integer) or data.dtype == np.bool_):
            raise ValueError(f"label values must be integers, got {data.dtype}")
        if data.dtype == np.bool_ or data.dtype.kind == "i":
            if data.size and data.min() < 0:
                raise ValueError("label values must be >= 0")
            data = data.astype(np.uint8 if data.size == 0 or data.max() < 256 else np.uint16)
        self.data = np.ascontiguousarray(data)
        self.spacing = tuple(float(s) for s in self.spacing)
        self.affine = np.diag([*self.spacing[::-1], 1.0]) if self.affine is None else np.asarray(self.affine, float)
        present = [int(v) for v in np.unique(self.data) if v != 0]
        self.names = {int(k): str(v) for k, v in self.names.items()}
        for v in present:
            self.names.setdefault(v, f"label_{v}")
        self.colors = {int(k): tuple(float(c) for c in v) for k, v in self.colors.items()}
        for v in self.names:
            self.colors.setdefault(v, default_color(v))
        self.meta = dict(self.meta)
        self.meta["warnings"] = list(self.meta.get("warnings", []))

    @property
    def shape(self) -> tuple[int, int, int]:
        """``(nz, ny, nx)``."""
        return self.data.shape  # type: ignore[return-value]

    @property
    def values(self) -> list[int]:
        """The label values that have a name, ascending."""
        return sorted(self.names)

    def value_of(self, name_or_value) -> int:
        """The label value of a structure name (or a value given as int / digit string); KeyError listing names."""
        if isinstance(name_or_value, (int, np.integer)) or str(name_or_value).isdigit():
            v = int(name_or_value)
            if v in self.names:
                return v
        else:
            for v, n in self.names.items():
                if n == name_or_value:
                    return v
        raise KeyError(choice_message("structure", name_or_value, self.names.values()))

    def mask(self, name_or_value) -> np.ndarray:
        """``(nz, ny, nx)`` bool: the voxels of one structure."""
        return self.data == self.value_of(name_or_value)

    def counts(self) -> dict[int, int]:
        """Voxels per label value (every named value, 0 when absent)."""
        c = np.bincount(self.data.ravel(), minlength=max(self.values, default=0) + 1)
        return {v: int(c[v]) for v in self.values}

    def volumes_ml(self) -> dict[int, float]:
        """Volume of each structure in millilitres (voxel count x voxel volume)."""
        voxel_ml = float(abs(np.linalg.det(self.affine[:3, :3]))) / 1000.0
        return {v: n * voxel_ml for v, n in self.counts().items()}

    def slab(self) -> LabelMap:
        """The labels on the grid of :meth:`Volume.slab <volumen.core.Volume.slab>` (itself without an axis of one
        sample)."""
        from ._volume import slab_grid

        data, affine = slab_grid(self.data, self.affine)
        return self if data is self.data else self.with_data(data, self.spacing, affine)

    def with_data(self, data: np.ndarray, spacing, affine) -> LabelMap:
        """The same names and colours on another grid."""
        return LabelMap(data, spacing, affine, dict(self.names), dict(self.colors), dict(self.meta))

    def __repr__(self) -> str:
        names = ", ".join(self.names.values())[:80]
        return f"LabelMap(shape(z,y,x)={self.shape}, {len(self.names)} structures: {names})"


@dataclass(eq=False)
class LabelLayer:
    """How a label map classifies a scan's samples in the ray caster (the scene's ``labels``).

    Parameters
    ----------
    labels : LabelMap
        On the scan's grid (:func:`volumen.io.labels_on_grid`).
    show : sequence of str or int, optional
        The structures drawn (all by default); the others are hidden (transparent).
    opacity : float or dict name -> float
        Opacity per reference step of each shown structure (0..1).
    colors : dict name -> (3,) float, optional
        Linear RGB overrides of the label map's colours.
    textured : bool
        False: each structure is a solid of its colour and opacity. True: its opacity follows the scan's
        transfer function (times ``opacity``), so the scan's texture shows through the structure's colour.
    scan : {"preset", "hidden"}
        Unlabelled voxels: drawn with the scan's own transfer function, or not at all.
    """

    labels: LabelMap
    show: tuple | None = None
    opacity: float | dict = 1.0
    colors: dict = field(default_factory=dict)
    textured: bool = False
    scan: str = "preset"

    def __post_init__(self) -> None:
        if self.scan not in ("preset", "hidden"):
            raise ValueError(f"LabelLayer.scan must be 'preset' or 'hidden', got {self.scan!r}")
        shown = self.labels.values if self.show is None else [self.labels.value_of(n) for n in self.show]
        self.show = tuple(shown)

    def table(self) -> np.ndarray:
        """``(max value + 1, 5)`` float32 rows ``(r, g, b, opacity, textured)`` per label value; row 0 is the
        unlabelled scan (``r = -1``: the transfer function's own colour and opacity; opacity 0: hidden)."""
        n = max(self.labels.values, default=0) + 1
        t = np.zeros((n, 5), np.float32)
        t[0] = (-1.0, -1.0, -1.0, 1.0 if self.scan == "preset" else 0.0, 1.0)
        for v in self.show:
            name = self.labels.names[v]
            op = self.opacity.get(name, 1.0) if isinstance(self.opacity, dict) else self.opacity
            rgb = self.colors.get(name, self.labels.colors[v])
            t[v] = (*rgb, float(op), 1.0 if self.textured else 0.0)
        return t
