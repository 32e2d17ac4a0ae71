"""Random numbers of the path tracer: an Owen-scrambled Sobol sequence per pixel, and a counter-based hash.

A path's random stream is a 64-bit ``key``: the pixel's seed in the high 32 bits, the sample index in the low
32 (:func:`path_key`). :func:`draw` gives dimension ``dim`` of the sample:

* dimensions below :data:`SOBOL_DIMS`: the first four dimensions of the Sobol sequence (Joe and Kuo's direction
  numbers), in pads of four, each pad's points shuffled and each dimension Owen-scrambled with a hash of the
  pixel's seed, the pad and the dimension (Burley, "Practical Hash-based Owen Scrambling", JCGT 9(4), 2020):
  over the samples of one pixel, each pad is a (0, 2)-sequence in every pair of its dimensions, so the first
  samples stratify the path's first decisions (free-flight distances, light choice, light and phase directions);
  every point is uniform on [0, 1), so the estimator stays unbiased;
* the others: a splitmix64 hash of (key, dim), independent uniform numbers (the extra steps of tracking).

Everything is integer arithmetic on arguments and a constant table: reproducible, independent of threads and of
how samples are split between calls, callable from a CUDA kernel.
"""

from __future__ import annotations

import numpy as np

from ...jit import njit

__all__ = ["path_key", "draw", "sobol_table", "SOBOL_DIMS", "sobol_point"]

#: dimensions drawn from the scrambled Sobol sequence (the rest from the hash)
SOBOL_DIMS = 32

_M1 = np.uint64(0xBF58476D1CE4E5B9)
_M2 = np.uint64(0x94D049BB133111EB)
_GOLD = np.uint64(0x9E3779B97F4A7C15)
_K1 = np.uint64(0xD6E8FEB86659FD93)
_MASK = np.uint64(0xFFFFFFFF)


def sobol_table() -> np.ndarray:
    """Direction numbers ``(4, 32)`` uint32 of Sobol's first four dimensions (Joe and Kuo, new-joe-kuo-6.21201:
    dimension 0 the van der Corput sequence; then (s, a, m) = (1, 0, [1]), (2, 1, [1, 3]), (3, 1, [1, 3, 1]))."""
    params = [(1, 0, [1]), (2, 1, [1, 3]), (3, 1, [1, 3, 1])]
    v = np.zeros((4, 32), np.uint64)
    v[0] = [1 << (31 - k) for k in range(32)]
    for d, (s, a, m) in enumerate(params, start=1):
        for k in range(32):
            if k < s:
                v[d, k] = m[k] << (31 - k)
            else:
                x = v[d, k - s] ^ (v[d, k - s] >> np.uint64(s))
                for j in range(1, s):
                    if (a >> (s - 1 - j)) & 1:
                        x ^= v[d, k - j]
                v[d, k] = x
    return v.astype(np.uint32)


_V = sobol_table()


@njit(cache=True, inline="always")
def _mix(h):
    """splitmix64 finalizer (uint64 -> uint64)."""
    h = (h ^ (h >> np.uint64(30))) * _M1
    h = (h ^ (h >> np.uint64(27))) * _M2
    return h ^ (h >> np.uint64(31))


@njit(cache=True)
def path_key(seed, pixel, sample):
    """The random stream of one pixel sample: a 32-bit hash of (seed, pixel index) over the sample index."""
    ps = _mix(np.uint64(seed) * _K1 + np.uint64(pixel)) & _MASK
    return (ps << np.uint64(32)) | (np.uint64(sample) & _MASK)


@njit(cache=True, inline="always")
def _reverse(x):
    """The 32 bits of ``x`` (held in a uint64) in reverse order."""
    x = ((x >> np.uint64(1)) & np.uint64(0x55555555)) | ((x & np.uint64(0x55555555)) << np.uint64(1))
    x = ((x >> np.uint64(2)) & np.uint64(0x33333333)) | ((x & np.uint64(0x33333333)) << np.uint64(2))
    x = ((x >> np.uint64(4)) & np.uint64(0x0F0F0F0F)) | ((x & np.uint64(0x0F0F0F0F)) << np.uint64(4))
    x = ((x >> np.uint64(8)) & np.uint64(0x00FF00FF)) | ((x & np.uint64(0x00FF00FF)) << np.uint64(8))
    return ((x >> np.uint64(16)) | (x << np.uint64(16))) & _MASK


@njit(cache=True, inline="always")
def _owen(x, seed):
    """Nested uniform scramble of the 32-bit ``x``: Laine and Karras's permutation on the reversed bits, as
    improved by Burley (its constants)."""
    x = _reverse(x)
    x = (x + seed) & _MASK
    x ^= (x * np.uint64(0x6C50B47C)) & _MASK
    x ^= (x * np.uint64(0xB82F1E52)) & _MASK
    x ^= (x * np.uint64(0xC7AFE638)) & _MASK
    x ^= (x * np.uint64(0x8D22F6E6)) & _MASK
    return _reverse(x)


@njit(cache=True, inline="always")
def sobol_point(index, dim):
    """The unscrambled 32-bit Sobol coordinate of point ``index`` in dimension ``dim`` (0..3)."""
    x = np.uint64(0)
    i = np.uint64(index)
    k = 0
    while i != np.uint64(0):
        if i & np.uint64(1):
            x ^= np.uint64(_V[dim, k])
        i >>= np.uint64(1)
        k += 1
    return x


@njit(cache=True)
def draw(key, dim):
    """Uniform in [0, 1): dimension ``dim`` of the sample ``key`` (:func:`path_key`)."""
    if dim < SOBOL_DIMS:
        ps = key >> np.uint64(32)
        pad = np.uint64(dim >> 2)
        seed = _mix(ps * _K1 + pad) & _MASK
        index = _owen(key & _MASK, seed)
        x = _owen(sobol_point(index, dim & 3), _mix(seed + np.uint64((dim & 3) + 1)) & _MASK)
        return np.float64(x) * (1.0 / 4294967296.0)
    return np.float64(_mix(key + np.uint64(dim) * _GOLD) >> np.uint64(11)) * (1.0 / 9007199254740992.0)
