"""Numba kernels for boulders: counter-based Gaussian noise per (seed, vertex)."""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ._calls import read_only_inputs
from ._rng_kernels import GOLDEN, _hash_normal, _mix64, _splitmix64


@read_only_inputs("out")
@njit(cache=True, parallel=True)
def _noise_kernel(seeds, out):
    """out[i, k] = a standard normal determined by (seeds[i], k) alone (Box-Muller on
    two 53-bit uniforms from splitmix64): a boulder's shape depends only on its seed."""
    n, m = out.shape
    for i in prange(n):
        s = _splitmix64(seeds[i])
        for k in range(m):
            out[i, k] = _hash_normal(_mix64(s ^ (np.uint64(k) * GOLDEN)))
