"""Numba kernels for boulders: counter-based Gaussian noise per (seed, vertex)."""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from .kernels import mix64

_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_TWO_POW_M53 = 1.0 / 9007199254740992.0


@njit(cache=True, parallel=True)
def _noise_kernel(seeds, out):
    """out[i, k] = a standard normal determined by (seeds[i], k) alone (Box-Muller on
    two 53-bit uniforms from splitmix64): a boulder's shape depends only on its seed."""
    n, m = out.shape
    for i in prange(n):
        s = mix64(seeds[i] + _GOLDEN)
        for k in range(m):
            a = mix64(s ^ (np.uint64(k) * _GOLDEN))
            b = mix64(a + _GOLDEN)
            u1 = ((a >> np.uint64(11)) + np.uint64(1)) * _TWO_POW_M53
            u2 = (b >> np.uint64(11)) * _TWO_POW_M53
            out[i, k] = np.sqrt(-2.0 * np.log(u1)) * np.cos(2.0 * np.pi * u2)
