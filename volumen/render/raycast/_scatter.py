"""Single scattering: the medium's coefficients and the per-light in-scattering weight.

The medium of the ``scattering`` and ``pathtrace`` models (docs/design.md section 3):
extinction ``sigma_t = (sigma_a + sigma_s) * tau(v) / ds0`` with ``tau`` the
transfer function's optical depth per reference step, albedo
``sigma_s / (sigma_a + sigma_s)`` times the transfer function's colour.

Radiance scattered toward the eye at a sample, per unit albedo and colour:
``S = ambient + diffuse * sum_l 4 pi p_HG(cos theta_l) E_l T_l`` with ``E_l`` the
light's colour x intensity x spot factor, ``T_l`` the transmittance to it, and
``ambient``, ``diffuse`` the Shading coefficients (the radiance of the uniform
environment, unshadowed, and the scale of the lights). The phase is taken
relative to the isotropic one (the ``4 pi``), so an isotropic medium in a light
of intensity 1 scatters like a diffuse surface lit head-on.
The ray caster composites ``(1 - A) * a * albedo * c * S`` per step, which is
the exact integral ``integral T_eye sigma_s c S ds`` when ``S`` and the medium
are constant over the step.
"""

from __future__ import annotations

import math

from ...jit import njit
from ..optics import hg_phase

__all__ = ["medium", "phase_weight"]


def medium(shading) -> tuple[float, float]:
    """``(kext, albedo)`` of a :class:`~volumen.core.Shading`: extinction scale and single-scattering albedo."""
    m = shading.scattering
    kext = float(m.sigma_a + m.sigma_s)
    return kext, float(m.sigma_s) / kext


@njit(cache=True, fastmath=True)
def phase_weight(lx, ly, lz, vx, vy, vz, g):
    """``4 pi p_HG`` for light arriving from unit direction ``L`` (sample -> light) and leaving toward ``V``
    (sample -> viewer): the light travels along ``-L``, so ``cos theta = -dot(L, V)``."""
    return 4.0 * math.pi * hg_phase(-(lx * vx + ly * vy + lz * vz), g)
