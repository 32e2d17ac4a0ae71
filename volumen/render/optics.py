"""The optical model, in one place (docs/design.md section 3).

Every renderer composes samples with these functions; they are Numba
``@njit`` functions of scalars only, so the CPU kernels and (later) CUDA
kernels call the same source.

* Emission-absorption, front to back, premultiplied:
  ``C += (1 - A) * a * c``; ``A += (1 - A) * a``.
* Opacity correction for a step ``ds`` against the reference step ``ds0``
  (one voxel): ``a' = 1 - (1 - a) ** (ds / ds0)``.
* Phong: ``c * (ka + sum_l I_l * v_l * kd * max(N.L_l, 0)) + sum_l I_l * v_l * ks * max(R_l.V, 0) ** n``
  with ``I_l`` the light's colour x intensity x spot factor and ``v_l`` its
  visibility (1 until shadows arrive). Two-sided: the normal is flipped
  toward the viewer before lighting, so either side of a boundary is lit the
  same way, and a light behind the visible side lights nothing; a normal
  at right angles to the view (up to ``core.FACING``) keeps its side.
* Spot factor: ``max(dot(L, D), 0) ** exponent`` with ``L`` the unit vector
  from the light to the sample, ``D`` the spot direction; exponent 0 is a
  point light (factor 1).
* Extinction: a reference-step opacity ``a`` is the optical depth
  ``tau = -ln(1 - a)`` per reference step, so ``1 - (1 - a) ** r = 1 - exp(-r tau)``
  and ``1 - opacity accumulated`` along a path is ``exp(-sum of tau * length / ds0)``
  (Beer-Lambert); shadows and scattering accumulate optical depth.
* Henyey-Greenstein phase, per steradian:
  ``p(cos) = (1 - g^2) / (4 pi (1 + g^2 - 2 g cos) ** 1.5)``, ``cos`` the cosine
  between the light's direction of travel and the scattered direction.
"""

from __future__ import annotations

import math

import numpy as np

from ..jit import njit

__all__ = ["correct_opacity", "composite", "spot_factor", "phong_terms", "power", "optical_depth", "hg_phase",
           "REFERENCE_STEP_VOXELS", "MAX_OPACITY"]

#: the transfer function's opacity is given per this many voxels (the smallest spacing)
REFERENCE_STEP_VOXELS = 1.0
#: opacities are clamped to this before taking optical depths (an opaque step is ~14 e-foldings)
MAX_OPACITY = 1.0 - 1e-6


@njit(cache=True, fastmath=True)
def correct_opacity(alpha, ratio):
    """Opacity of a step ``ratio = ds / ds0`` times the reference step: ``1 - (1 - alpha) ** ratio``."""
    if alpha >= 1.0:
        return 1.0
    return 1.0 - (1.0 - alpha) ** ratio


@njit(cache=True, fastmath=True)
def composite(acc_r, acc_g, acc_b, acc_a, r, g, b, a):
    """Front-to-back "over": add a sample of premultiplied colour ``(r, g, b)`` and opacity ``a``
    behind the accumulated ``(acc_r, acc_g, acc_b, acc_a)``; returns the new accumulation."""
    t = 1.0 - acc_a
    return acc_r + t * r, acc_g + t * g, acc_b + t * b, acc_a + t * a


@njit(cache=True, fastmath=True)
def spot_factor(lx, ly, lz, dx, dy, dz, exponent):
    """``max(dot(L, D), 0) ** exponent``; ``L`` = unit vector light -> sample, ``D`` = unit spot direction."""
    if exponent == 0.0:
        return 1.0
    c = lx * dx + ly * dy + lz * dz
    if c <= 0.0:
        return 0.0
    return power(c, exponent)


@njit(cache=True, fastmath=True)
def power(x, e):
    """``x ** e`` for x >= 0; by repeated squaring when ``e`` is a whole number up to 1024 (fast, exact
    to rounding), else through ``pow``."""
    n = int(e)
    if n == e and 0 <= n <= 1024:
        r = 1.0
        while n > 0:
            if n & 1:
                r *= x
            x *= x
            n >>= 1
        return r
    return x ** e


@njit(cache=True, fastmath=True)
def phong_terms(n, light, view, shininess):
    """Diffuse and specular factors of one light.

    Parameters
    ----------
    n : (nx, ny, nz) unit normal, already flipped toward the viewer (two-sided lighting)
    light : (lx, ly, lz) unit vector from the sample toward the light
    view : (vx, vy, vz) unit vector from the sample toward the viewer
    shininess : specular exponent

    Returns
    -------
    (diffuse, specular) : ``max(N.L, 0)`` and ``max(R.V, 0) ** shininess`` (0 when N.L <= 0),
    ``R = 2 (N.L) N - L``.
    """
    nx, ny, nz = n
    lx, ly, lz = light
    vx, vy, vz = view
    ndl = nx * lx + ny * ly + nz * lz
    if ndl <= 0.0:
        return 0.0, 0.0
    rx = 2.0 * ndl * nx - lx
    ry = 2.0 * ndl * ny - ly
    rz = 2.0 * ndl * nz - lz
    rdv = rx * vx + ry * vy + rz * vz
    if rdv <= 0.0:
        return ndl, 0.0
    return ndl, power(rdv, shininess)


@njit(cache=True, fastmath=True)
def optical_depth(alpha):
    """Optical depth ``-ln(1 - alpha)`` of an opacity (alpha clamped to ``MAX_OPACITY``)."""
    return -np.log(1.0 - min(max(alpha, 0.0), MAX_OPACITY))


@njit(cache=True, fastmath=True)
def hg_phase(cos_theta, g):
    """Henyey-Greenstein phase function (1/sr) at ``cos_theta`` for anisotropy ``g`` in (-1, 1)."""
    d = 1.0 + g * g - 2.0 * g * cos_theta
    return (1.0 - g * g) / (4.0 * math.pi * d * math.sqrt(d))
