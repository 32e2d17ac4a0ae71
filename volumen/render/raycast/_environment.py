"""The environment light in the kernels: an equirectangular radiance map, its sampling tables, its SH projection.

:func:`pack_environment` turns the scene's :class:`~volumen.core.Environment` (resolved: ``uniform``,
``studio`` or ``map``) into the arrays below; ``Settings.env_mode`` is 0 for ``uniform`` (the kernels use the
uniform ambient radiance ``Settings.ambient``, the same in every direction) and 1 otherwise.

* ``env`` (He, We, 3) float32: radiance per pixel of the map, row 0 at the zenith of the map's frame, column
  ``c`` at azimuth ``phi = 2 pi (c + 0.5) / We`` from its x axis toward its y axis;
* ``env_basis`` (3, 3) float64: the map frame's x, y, z axes (rows) in world space: the camera's (right, back,
  up) for the studio sky, world (x, y, z) turned by ``rotation`` about z for a map;
* ``env_cdf`` (He + 1, We + 1) float64: the cumulative distributions of importance sampling
  (:func:`sampling_tables`; Pharr et al., PBRT 3rd ed. 14.2.4): over rows in row 0, over the columns of row i
  in row 1 + i, proportional to luminance x solid angle;
* ``env_sh`` (9, 3) float64: the map's real spherical-harmonic coefficients to order 2 in world space
  (Ramamoorthi and Hanrahan 2001): the ray-cast models' ambient term, the irradiance
  ``E(n) / pi = sum_lm A_l L_lm Y_lm(n) / pi`` (Phong) or the phase-weighted radiance
  ``sum_lm g^l L_lm Y_lm(d)`` (single scattering with Henyey-Greenstein's phase: its Legendre coefficients
  are ``g^l``).
"""

from __future__ import annotations

import math

import numpy as np

from ...core import studio_sky
from ...jit import njit

__all__ = ["pack_environment", "sampling_tables", "sh_project", "sh_basis", "env_radiance", "env_sample",
           "env_pdf", "sh_irradiance", "sh_phase", "UNIFORM_ENV"]

#: resolution of the studio sky's map (rows, columns)
SKY_SHAPE = (32, 64)
#: largest map handed to the kernels (rows); larger maps are box-averaged down
MAX_ROWS = 256
_SH_A = (math.pi, 2.0 * math.pi / 3.0, 2.0 * math.pi / 3.0, 2.0 * math.pi / 3.0, math.pi / 4.0, math.pi / 4.0,
         math.pi / 4.0, math.pi / 4.0, math.pi / 4.0)


def _uniform_arrays():
    env = np.zeros((2, 2, 3), np.float32)
    cdf = np.tile(np.linspace(0.0, 1.0, 3), (3, 1))
    return env, np.eye(3), cdf, np.zeros((9, 3))


#: the arrays of a ``uniform`` environment (one object: a device keeps it between frames)
UNIFORM_ENV = _uniform_arrays()


def sh_basis(x, y, z) -> np.ndarray:
    """The 9 real SH basis functions to order 2 at unit directions ``(x, y, z)`` (arrays): ``(9, ...)``."""
    return np.stack([0.282095 + 0 * x, 0.488603 * y, 0.488603 * z, 0.488603 * x, 1.092548 * x * y,
                     1.092548 * y * z, 0.315392 * (3 * z * z - 1), 1.092548 * x * z, 0.546274 * (x * x - y * y)])


def _directions(he: int, we: int):
    """Pixel-centre unit directions ``(x, y, z)`` of an (he, we) map in its frame, and each pixel's solid angle."""
    th = (np.arange(he) + 0.5) * math.pi / he
    ph = (np.arange(we) + 0.5) * 2 * math.pi / we
    t, p = np.meshgrid(th, ph, indexing="ij")
    sa = np.sin(t) * (math.pi / he) * (2 * math.pi / we)
    return np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t), sa


def sh_project(env: np.ndarray, basis: np.ndarray) -> np.ndarray:
    """SH coefficients ``(9, 3)`` in world space of map ``env`` (He, We, 3) whose frame axes are ``basis``'s rows."""
    he, we = env.shape[:2]
    x, y, z, sa = _directions(he, we)
    w = np.stack([x, y, z], -1) @ np.asarray(basis)  # world directions
    ys = sh_basis(w[..., 0], w[..., 1], w[..., 2])
    return np.einsum("khw,hw,hwc->kc", ys, sa, env.astype(np.float64))


def sampling_tables(env: np.ndarray) -> np.ndarray:
    """``(He + 1, We + 1)`` cumulative tables: row 0, columns 0..He, the marginal over rows; row 1 + i the
    conditional over the columns of row i; each from 0 to 1, proportional to luminance x sin(theta)."""
    he, we = env.shape[:2]
    lum = env[..., 0] * 0.2126 + env[..., 1] * 0.7152 + env[..., 2] * 0.0722
    w = np.maximum(lum.astype(np.float64), 0.0) * np.sin((np.arange(he) + 0.5) * math.pi / he)[:, None]
    w = w + 1e-6 * max(float(w.max()), 1e-12)  # every direction has a chance: the estimator stays unbiased
    out = np.zeros((he + 1, we + 1))
    rows = w.sum(axis=1)
    out[0, 1:he + 1] = np.cumsum(rows) / rows.sum()
    out[1:, 1:] = np.cumsum(w, axis=1) / rows[:, None]
    out[0, he:] = 1.0
    out[1:, we] = 1.0
    return out


def _shrink(img: np.ndarray) -> np.ndarray:
    """Box-average a map down to at most :data:`MAX_ROWS` rows (and twice as many columns)."""
    f = int(math.ceil(img.shape[0] / MAX_ROWS))
    if f <= 1:
        return img
    he, we = img.shape[0] // f, img.shape[1] // f
    return img[:he * f, :we * f].reshape(he, f, we, f, 3).mean(axis=(1, 3))


def pack_environment(env, camera):
    """``(envmode, (env, envbasis, envcdf, envsh))`` of a resolved :class:`~volumen.core.Environment`."""
    if env.kind == "uniform":
        return 0, UNIFORM_ENV
    rot = math.radians(env.rotation)
    if env.kind == "studio":
        r, u, f = camera.basis()
        basis = np.stack([r, -np.asarray(f), u])
        x, y, z, _ = _directions(*SKY_SHAPE)
        img = studio_sky(z)
    else:
        if env.image is None:
            raise ValueError(f"environment map {env.map!r} was not read: read it into Environment.image "
                             "(volumen.io.read_environment)")
        basis = np.array([[math.cos(rot), math.sin(rot), 0.0], [-math.sin(rot), math.cos(rot), 0.0],
                          [0.0, 0.0, 1.0]])
        img = _shrink(np.asarray(env.image, np.float64))
    if env.kind == "studio" and rot:
        c, s = math.cos(rot), math.sin(rot)
        basis = np.stack([c * basis[0] + s * basis[1], -s * basis[0] + c * basis[1], basis[2]])
    img = np.ascontiguousarray(img * env.intensity, dtype=np.float32)
    return 1, (img, np.ascontiguousarray(basis, np.float64), sampling_tables(img), sh_project(img, basis))


@njit(cache=True, fastmath=True, inline="always")
def _local(b, dx, dy, dz):
    """World direction -> the map frame's (x, y, z)."""
    return (b[0, 0] * dx + b[0, 1] * dy + b[0, 2] * dz, b[1, 0] * dx + b[1, 1] * dy + b[1, 2] * dz,
            b[2, 0] * dx + b[2, 1] * dy + b[2, 2] * dz)


@njit(cache=True, fastmath=True, inline="always")
def _pixel(env, b, dx, dy, dz):
    """(row, column, sin theta) of the map pixel seen along world direction d."""
    he, we = env.shape[0], env.shape[1]
    x, y, z = _local(b, dx, dy, dz)
    th = math.acos(min(max(z, -1.0), 1.0))
    ph = math.atan2(y, x)
    if ph < 0.0:
        ph += 2.0 * math.pi
    i = min(int(th * he / math.pi), he - 1)
    j = min(int(ph * we / (2.0 * math.pi)), we - 1)
    return i, j, math.sin(th)


@njit(cache=True, fastmath=True)
def env_radiance(a, dx, dy, dz):
    """Radiance ``(r, g, b)`` of the environment seen along world unit direction d."""
    i, j, _ = _pixel(a.env, a.env_basis, dx, dy, dz)
    return a.env[i, j, 0], a.env[i, j, 1], a.env[i, j, 2]


@njit(cache=True, fastmath=True, inline="always")
def env_pdf(a, dx, dy, dz):
    """Density (per steradian) with which :func:`env_sample` draws world direction d."""
    c = a.env_cdf
    he, we = a.env.shape[0], a.env.shape[1]
    i, j, st = _pixel(a.env, a.env_basis, dx, dy, dz)
    p = (c[0, i + 1] - c[0, i]) * (c[i + 1, j + 1] - c[i + 1, j])
    return p * he * we / (2.0 * math.pi * math.pi * max(st, 1e-6))


@njit(cache=True, fastmath=True, inline="always")
def _search(c, row, n, u):
    """The k in [0, n) with c[row, k] <= u < c[row, k + 1] (binary search of a cumulative row)."""
    lo, hi = 0, n
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if c[row, mid] <= u:
            lo = mid
        else:
            hi = mid
    return lo


@njit(cache=True, fastmath=True, inline="always")
def env_sample(a, u1, u2):
    """A world direction drawn proportionally to luminance x solid angle: ``(dx, dy, dz, pdf per sr)``."""
    c = a.env_cdf
    he, we = a.env.shape[0], a.env.shape[1]
    i = _search(c, 0, he, u1)
    fi = (u1 - c[0, i]) / max(c[0, i + 1] - c[0, i], 1e-300)
    j = _search(c, i + 1, we, u2)
    fj = (u2 - c[i + 1, j]) / max(c[i + 1, j + 1] - c[i + 1, j], 1e-300)
    th = (i + min(max(fi, 0.0), 1.0)) * math.pi / he
    ph = (j + min(max(fj, 0.0), 1.0)) * 2.0 * math.pi / we
    st = math.sin(th)
    x, y, z = st * math.cos(ph), st * math.sin(ph), math.cos(th)
    b = a.env_basis
    dx = b[0, 0] * x + b[1, 0] * y + b[2, 0] * z
    dy = b[0, 1] * x + b[1, 1] * y + b[2, 1] * z
    dz = b[0, 2] * x + b[1, 2] * y + b[2, 2] * z
    p = (c[0, i + 1] - c[0, i]) * (c[i + 1, j + 1] - c[i + 1, j])
    return dx, dy, dz, p * he * we / (2.0 * math.pi * math.pi * max(st, 1e-6))


@njit(cache=True, fastmath=True, inline="always")
def _sh_sum(sh, x, y, z, w0, w1, w2):
    """``sum_lm w_l sh[lm] Y_lm(x, y, z)`` per channel."""
    y0 = 0.282095 * w0
    y1, y2, y3 = 0.488603 * y * w1, 0.488603 * z * w1, 0.488603 * x * w1
    y4, y5 = 1.092548 * x * y * w2, 1.092548 * y * z * w2
    y6, y7, y8 = 0.315392 * (3.0 * z * z - 1.0) * w2, 1.092548 * x * z * w2, 0.546274 * (x * x - y * y) * w2
    r = y0 * sh[0, 0] + y1 * sh[1, 0] + y2 * sh[2, 0] + y3 * sh[3, 0] + y4 * sh[4, 0] + y5 * sh[5, 0] \
        + y6 * sh[6, 0] + y7 * sh[7, 0] + y8 * sh[8, 0]
    g = y0 * sh[0, 1] + y1 * sh[1, 1] + y2 * sh[2, 1] + y3 * sh[3, 1] + y4 * sh[4, 1] + y5 * sh[5, 1] \
        + y6 * sh[6, 1] + y7 * sh[7, 1] + y8 * sh[8, 1]
    b = y0 * sh[0, 2] + y1 * sh[1, 2] + y2 * sh[2, 2] + y3 * sh[3, 2] + y4 * sh[4, 2] + y5 * sh[5, 2] \
        + y6 * sh[6, 2] + y7 * sh[7, 2] + y8 * sh[8, 2]
    return max(r, 0.0), max(g, 0.0), max(b, 0.0)


@njit(cache=True, fastmath=True)
def sh_irradiance(a, nx, ny, nz):
    """``E(n) / pi``: the environment's irradiance on a surface of unit normal n over pi (its diffuse radiance for
    albedo 1); the mean radiance where the normal is (0, 0, 0)."""
    if nx == 0.0 and ny == 0.0 and nz == 0.0:
        return _sh_sum(a.env_sh, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0)
    return _sh_sum(a.env_sh, nx, ny, nz, 1.0, 2.0 / 3.0, 0.25)


@njit(cache=True, fastmath=True)
def sh_phase(a, dx, dy, dz, g):
    """``integral L(w) p_HG(w . d) dw``: the environment's light that a Henyey-Greenstein medium of anisotropy
    g scatters back toward an eye looking along unit direction d (eye -> sample), unshadowed."""
    return _sh_sum(a.env_sh, dx, dy, dz, 1.0, g, g * g)
