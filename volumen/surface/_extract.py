"""From a volume to a finished surface: marching cubes, clean-up, smoothing, decimation (for the CLI)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..core import Volume
from ._decimate import decimate
from ._marching_cubes import marching_cubes
from ._mesh import Mesh
from ._mesh_components import largest_component
from ._smooth import taubin_smooth

__all__ = ["extract_mesh", "is_mask"]


def is_mask(volume: Volume) -> bool:
    """Whether ``volume`` is a 0/1 mask (integers or booleans in 0..1), whose boundary :func:`extract_mesh` meshes
    without a level."""
    lo, hi = volume.value_range()
    return bool(lo >= 0 and hi <= 1 and volume.dtype.kind in "biu")


def extract_mesh(volume: Volume, iso: float | None = None, mask=None, *, smooth_iterations: int = 10,
                 target_triangles: int | None = None, largest_only: bool = False, step: int = 1,
                 progress: Callable[[float], None] | None = None) -> Mesh:
    """A surface mesh of a volume, ready to save or show.

    Parameters
    ----------
    volume : Volume
        The scalar volume; vertices come out in its world RAS+ millimetres.
    iso : float, optional
        Iso level in the volume's units (HU for CT). With ``mask`` too, only the part of
        the isosurface inside the mask is kept.
    mask : Volume or (nz, ny, nx) bool array, optional
        A mask on the volume's grid. Without ``iso``, the mask's own boundary is meshed
        (at level 0.5 of the 0/1 mask; smoothing removes its voxel steps).
    smooth_iterations : int
        Taubin smoothing iterations (lambda 0.5, mu -0.53); 0 for none.
    target_triangles : int, optional
        Decimate to about this many triangles.
    largest_only : bool
        Keep only the connected piece with the most triangles.
    step : int
        Marching-cubes sampling step in voxels.
    progress : callable, optional
        Called with the fraction done, a float rising from 0.0 to 1.0.

    Returns
    -------
    Mesh
        ``meta`` records the level, the stages run and their triangle counts.

    Raises
    ------
    ValueError
        Without ``iso`` and ``mask`` when the volume is not a 0/1 mask itself, or when
        the surface is empty.
    """
    report = progress if progress is not None else (lambda fraction: None)
    report(0.0)
    if not isinstance(volume, Volume):
        raise TypeError(f"extract_mesh takes a volumen Volume, got {type(volume).__name__}")
    mask_data = None
    if mask is not None:
        mask_data = np.asarray(mask.data if isinstance(mask, Volume) else mask)
        if mask_data.shape != volume.shape:
            raise ValueError(f"mask shape {mask_data.shape} differs from the volume's {volume.shape}")
        mask_data = mask_data.astype(bool, copy=False)
    if iso is None and mask_data is None:
        if not is_mask(volume):
            raise ValueError("extract_mesh needs an iso level (in the volume's units) or a mask")
        mesh = marching_cubes(volume, 0.5, step=step)
    elif iso is None:
        mesh = marching_cubes(volume.with_data(mask_data.view(np.uint8)), 0.5, step=step)
    else:
        mesh = marching_cubes(volume, float(iso), mask=mask_data, step=step)
    stages = {"marching_cubes": mesh.n_faces}
    report(0.5)
    if mesh.n_faces == 0:
        raise ValueError(f"the surface is empty at level {mesh.meta['level']:g}")
    if largest_only:
        mesh = largest_component(mesh)
        stages["largest_only"] = mesh.n_faces
    report(0.6)
    if smooth_iterations:
        mesh = taubin_smooth(mesh, smooth_iterations)
        stages["taubin_smooth"] = mesh.n_faces
    report(0.8)
    if target_triangles is not None:
        mesh = decimate(mesh, target_triangles)
        stages["decimate"] = mesh.n_faces
    report(1.0)
    mesh.meta.update(level=0.5 if iso is None else float(iso), stages=stages, source=volume.name)
    return mesh
