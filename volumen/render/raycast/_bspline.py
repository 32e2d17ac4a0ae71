"""Tricubic B-spline reconstruction in its fast form, and the reconstruction pieces the kernels call.

Thick slices show through trilinear reconstruction: its value is continuous but its gradient jumps at every
voxel plane, so the wall of a vessel scanned in 1.5 mm slices carries a terrace per slice, concentric rings
down an endoscope's view at any sampling rate. The cubic B-spline is twice continuously differentiable.

**Which B-spline.** This is the *approximating* cubic B-spline: the voxel values are its coefficients, with no
prefilter (scipy's ``map_coordinates(order=3, prefilter=False)``), as cinematic renderers offer it as a
smoothing option. Each value is a convex combination of the 4^3 voxels around it, so it never overshoots a
sharp edge (contrast against tissue: the interpolating spline rings there, and a transfer function shows the
ring as a halo), it stays inside the voxels' range (the skipping grids of ``_precompute.build_blocks``, dilated
by one voxel, and the path tracer's majorants bound it as they bound trilinear samples), and it needs no
prefiltered copy of the volume. It smooths: a kernel of variance 1/3 voxel^2 per axis; it reproduces linear
fields exactly and turns a polynomial ``p`` of degree at most 3 into ``p + laplacian(p) / 6`` (index units).
A surface keeps its place where it is flat; a curved one moves toward its centre of curvature by about
``1 / (3 R)`` voxel on a sphere of radius ``R`` voxels, ``1 / (6 R)`` on a tube (a vessel of radius 4 voxels: 0.04).

**The fast form** (Sigg and Hadwiger, "Fast third-order texture filtering", GPU Gems 2, ch. 20). Along one
axis, at ``x = i + a`` (``i = floor x``), the weights of voxels ``i - 1 .. i + 2`` are
``w0 = (1 - a)^3 / 6``, ``w1 = (3 a^3 - 6 a^2 + 4) / 6``, ``w2 = (-3 a^3 + 3 a^2 + 3 a + 1) / 6``,
``w3 = a^3 / 6``; two linear lookups carry them: ``g0 = w0 + w1`` at ``h0 = i - 1 + w1 / g0`` and
``g1 = w2 + w3`` at ``h1 = i + 1 + w3 / g1``. In 3-D, eight trilinear lookups (``_sample.trilinear``: the
same clamped lookup as the trilinear path, the GPU's texture unit on OpenGL) weighted by the products of
``g``. The derivative weights ``w'`` sum to zero: ``q = w2' + w3' = -(w0' + w1') = 1/2 + a - a^2``, so the
derivative along an axis is the same blend with weights ``(-q, q)`` at ``e0 = i - 1 + w1' / (w0' + w1')`` and
``e1 = i + 1 + w3' / q``: a gradient is 24 lookups. Lookups clamp to the volume's edge, so the volume is
extended by its edge values (scipy's ``mode="nearest"``).

**The pieces.** :func:`reconstruct` (a value in table units) and :func:`normal` (the gradient as the
shading reads it) take the frame's reconstruction tag (``Settings.recon``, ``_pieces``): ``Trilinear`` gives
``_sample.sample_table`` and ``_normals.sample_normal`` (normals from the per-voxel codes), ``BSpline`` the
functions here (gradients of the B-spline itself, no codes). Labels and a colour volume's RGB stay trilinear.
"""

from __future__ import annotations

import math

from ...jit import njit
from ._normals import sample_normal
from ._pieces import BSpline, Trilinear, piece
from ._sample import _cell, sample_table, trilinear

__all__ = ["bspline_value", "bspline_gradient", "reconstruct", "normal"]


@njit(cache=True, fastmath=True, inline="always")
def _value_taps(x, n):
    """One axis of the value: ``(cell at h0, cell at h1, g0, g1)`` (cells as ``_sample._cell``)."""
    i = math.floor(x)
    a = x - i
    w1 = (4.0 + a * a * (3.0 * a - 6.0)) / 6.0
    g0 = (1.0 - a) ** 3 / 6.0 + w1
    g1 = 1.0 - g0
    return _cell(i - 1.0 + w1 / g0, n), _cell(i + 1.0 + a * a * a / (6.0 * g1), n), g0, g1


@njit(cache=True, fastmath=True, inline="always")
def _slope_taps(x, n):
    """One axis of the derivative: ``(cell at e0, cell at e1, -q, q)``."""
    i = math.floor(x)
    a = x - i
    q = 0.5 + a - a * a
    return _cell(i - 1.0 + a * (4.0 - 3.0 * a) / (2.0 * q), n), _cell(i + 1.0 + a * a / (2.0 * q), n), -q, q


@njit(cache=True, fastmath=True)
def _blend(vol, tx, ty, tz):
    """``sum w_x w_y w_z trilinear(x, y, z)`` over the two taps of each axis (``_value_taps`` / ``_slope_taps``):
    eight trilinear lookups."""
    x0, x1, wx0, wx1 = tx
    y0, y1, wy0, wy1 = ty
    z0, z1, wz0, wz1 = tz
    r00 = wx0 * trilinear(vol, x0, y0, z0) + wx1 * trilinear(vol, x1, y0, z0)
    r10 = wx0 * trilinear(vol, x0, y1, z0) + wx1 * trilinear(vol, x1, y1, z0)
    r01 = wx0 * trilinear(vol, x0, y0, z1) + wx1 * trilinear(vol, x1, y0, z1)
    r11 = wx0 * trilinear(vol, x0, y1, z1) + wx1 * trilinear(vol, x1, y1, z1)
    return wz0 * (wy0 * r00 + wy1 * r10) + wz1 * (wy0 * r01 + wy1 * r11)


@njit(cache=True, fastmath=True)
def bspline_value(vol, x, y, z):
    """The cubic B-spline of ``vol[z, y, x]`` (its voxels the coefficients) at index position (x, y, z)."""
    nz, ny, nx = vol.shape
    return _blend(vol, _value_taps(x, nx), _value_taps(y, ny), _value_taps(z, nz))


@njit(cache=True, fastmath=True)
def bspline_gradient(vol, x, y, z):
    """``(d/di, d/dj, d/dk)`` of :func:`bspline_value` at (x, y, z), in units of ``vol`` per voxel."""
    nz, ny, nx = vol.shape
    tx, ty, tz = _value_taps(x, nx), _value_taps(y, ny), _value_taps(z, nz)
    return (_blend(vol, _slope_taps(x, nx), ty, tz), _blend(vol, tx, _slope_taps(y, ny), tz),
            _blend(vol, tx, ty, _slope_taps(z, nz)))


reconstruct = piece("reconstruct", "vol, u0, ufac, x, y, z, nearest",
                    "-> the value at index position (x, y, z) in table units (``_sample.sample_table``)")
normal = piece("normal", "a, x, y, z, nearest, want_dir, want_mag",
               "-> (gx, gy, gz, magnitude code) at (x, y, z) as ``_normals.sample_normal`` gives them")


@reconstruct.register(Trilinear)
@njit(cache=True, fastmath=True, inline="always")
def _trilinear_value(vol, u0, ufac, x, y, z, nearest):
    return sample_table(vol, u0, ufac, x, y, z, nearest)


@reconstruct.register(BSpline)
@njit(cache=True, fastmath=True, inline="always")
def _bspline_value(vol, u0, ufac, x, y, z, nearest):
    return (bspline_value(vol, x, y, z) - u0) * ufac


@normal.register(Trilinear)
@njit(cache=True, fastmath=True, inline="always")
def _trilinear_normal(a, x, y, z, nearest, want_dir, want_mag):
    return sample_normal(a, x, y, z, nearest, want_dir, want_mag)


@normal.register(BSpline)
@njit(cache=True, fastmath=True, inline="always")
def _bspline_normal(a, x, y, z, nearest, want_dir, want_mag):
    """The B-spline's world gradient (``a.gradient_matrix``: index -> world gradient matrix, 1 / gmax) as a unit
    direction (0 where it vanishes, as the codes' code 0) and its magnitude code ``127 sqrt(|g| / gmax)``
    (``_normals``)."""
    gi, gj, gk = bspline_gradient(a.vol, x, y, z)
    m = a.gradient_matrix
    gx = m[0, 0] * gi + m[0, 1] * gj + m[0, 2] * gk
    gy = m[1, 0] * gi + m[1, 1] * gj + m[1, 2] * gk
    gz = m[2, 0] * gi + m[2, 1] * gj + m[2, 2] * gk
    g = math.sqrt(gx * gx + gy * gy + gz * gz)
    code = 0.0
    if want_mag:
        code = 127.0 * math.sqrt(min(g * m[3, 0], 1.0))
    if g <= 1e-6 or not want_dir:
        return 0.0, 0.0, 0.0, code
    return gx / g, gy / g, gz / g, code

