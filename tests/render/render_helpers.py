"""Helpers for the renderer tests: small generated volumes and axis-aligned orthographic cameras."""

from __future__ import annotations

import numpy as np

from volumen.core import Camera, Volume

# view -> (direction from target to eye, up)
_AXES = {"superior": ((0, 0, 1), (0, 1, 0)), "anterior": ((0, 1, 0), (0, 0, 1))}


def axis_camera(volume: Volume, view: str = "superior") -> tuple[Camera, tuple[int, int]]:
    """Orthographic camera along a voxel axis whose pixel centres fall on voxel centres (unit spacing).

    superior: image (W, H) = (nx, ny), column c <-> x index c, row r <-> y index ny-1-r.
    anterior: image (W, H) = (nx, nz), column c <-> x index nx-1-c, row r <-> z index nz-1-r.
    """
    nz, ny, nx = volume.shape
    back, up = (np.array(v, float) for v in _AXES[view])
    size = (nx, ny) if view == "superior" else (nx, nz)
    c = volume.center
    cam = Camera(position=tuple(c + back * (volume.diagonal + 10)), target=tuple(c), up=tuple(up),
                 projection="orthographic", parallel_scale=size[1] / 2 * volume.spacing[0])
    return cam, size


def sphere_volume(n: int = 40, radius: float = 12.0, inside: float = 1000.0, outside: float = -1000.0,
                  smooth: float = 1.0, dtype=np.int16) -> Volume:
    """A ball of value ``inside`` in ``outside``, edges smoothed over ``smooth`` voxels (tanh), unit spacing.

    int16 (rounded HU) by default, as CT is stored: the ray caster compiles one kernel per (mode, shading and
    sample type), and the phantoms' int16 kernels are then the ones these tests run (float32 ones would double
    the suite's cold compilation)."""
    z, y, x = np.mgrid[:n, :n, :n].astype(np.float64)
    c = (n - 1) / 2
    r = np.sqrt((x - c) ** 2 + (y - c) ** 2 + (z - c) ** 2)
    w = 0.5 * (1 - np.tanh((r - radius) / smooth))
    data = outside + (inside - outside) * w
    data = np.rint(data).astype(dtype) if np.issubdtype(np.dtype(dtype), np.integer) else data.astype(dtype)
    return Volume(data, spacing=(1.0, 1.0, 1.0), modality="CT", units="HU")


def three_lights(center) -> tuple:
    """Three different lights around ``center`` (world mm): a point light, a spot and a narrow blue spot."""
    from volumen.core import Light

    c = np.asarray(center, float)
    return (Light(position=tuple(c + [80, 60, 40]), intensity=0.3, color=(1, 0.8, 0.6)),
            Light(position=tuple(c + [-70, 50, -20]), direction=(0.7, -0.5, 0.2), exponent=4.0, intensity=0.35),
            Light(position=tuple(c + [0, 90, 0]), direction=(0, -1, 0), exponent=12.0, intensity=0.25,
                  color=(0.5, 0.7, 1.0)))
