"""Numba kernel of :mod:`craters.counter`: Philox4x64-10 (Salmon et al. 2011)."""

from __future__ import annotations

import numpy as np
from numba import njit, prange

_M0 = np.uint64(0xD2E7470EE14C6C93)
_M1 = np.uint64(0xCA5A826395121157)
_W0 = np.uint64(0x9E3779B97F4A7C15)
_W1 = np.uint64(0xBB67AE8584CAA73B)
_LOW32 = np.uint64(0xFFFFFFFF)
_S32 = np.uint64(32)


@njit(cache=True, inline="always")
def _mulhilo(a, b):
    """(high, low) 64-bit halves of the 128-bit product of two uint64."""
    a_lo = a & _LOW32
    a_hi = a >> _S32
    b_lo = b & _LOW32
    b_hi = b >> _S32
    p0 = a_lo * b_lo
    p1 = a_lo * b_hi
    p2 = a_hi * b_lo
    p3 = a_hi * b_hi
    carry = ((p0 >> _S32) + (p1 & _LOW32) + (p2 & _LOW32)) >> _S32
    return p3 + (p1 >> _S32) + (p2 >> _S32) + carry, a * b


@njit(cache=True, parallel=True)
def _philox_kernel(counters, keys, out):
    """out[i] = Philox4x64-10(counters[i], keys[i]); rows independent."""
    for i in prange(counters.shape[0]):
        c0 = counters[i, 0]
        c1 = counters[i, 1]
        c2 = counters[i, 2]
        c3 = counters[i, 3]
        k0 = keys[i, 0]
        k1 = keys[i, 1]
        for r in range(10):
            if r > 0:
                k0 = k0 + _W0
                k1 = k1 + _W1
            hi0, lo0 = _mulhilo(_M0, c0)
            hi1, lo1 = _mulhilo(_M1, c2)
            c0, c1, c2, c3 = hi1 ^ c1 ^ k0, lo1, hi0 ^ c3 ^ k1, lo0
        out[i, 0] = c0
        out[i, 1] = c1
        out[i, 2] = c2
        out[i, 3] = c3
