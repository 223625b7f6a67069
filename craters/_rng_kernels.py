"""Counter-based random numbers for numba kernels: splitmix64 and a Gaussian per hash.

A deviate is a pure function of the integers that key it (a seed, a stream, a level,
an index ...), never of the order in which a kernel visits them, of the thread count or
of the tiling (DESIGN §3). The mix is Steele, Lea & Flood's (2014) splitmix64 (the
``java.util.SplittableRandom`` finaliser, variant 13); a 64-bit hash gives two 53-bit
uniforms and one standard normal by Box–Muller (cosine branch).
"""

from __future__ import annotations

import numpy as np
from numba import njit

GOLDEN = np.uint64(0x9E3779B97F4A7C15)  # the splitmix64 gamma, 2**64 / golden ratio
_S11 = np.uint64(11)
_ONE = np.uint64(1)
_TWO_POW_M53 = 1.0 / 9007199254740992.0  # 2**-53
_TWO_PI = 2.0 * np.pi


@njit(cache=True, inline="always")
def _mix64(z):
    """The splitmix64 finaliser (uint64 -> uint64)."""
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return z ^ (z >> np.uint64(31))


@njit(cache=True, inline="always")
def _splitmix64(x):
    """The splitmix64 step: add the golden gamma, then the finaliser."""
    return _mix64(x + GOLDEN)


@njit(cache=True, inline="always")
def _hash_normal(a):
    """A standard normal deviate from the 64-bit hash ``a``: u1 = the top 53 bits of
    ``a`` in (0, 1], u2 = the top 53 bits of ``splitmix64(a)`` in [0, 1), Box–Muller."""
    b = _splitmix64(a)
    u1 = ((a >> _S11) + _ONE) * _TWO_POW_M53  # (0, 1]
    u2 = (b >> _S11) * _TWO_POW_M53  # [0, 1)
    return np.sqrt(-2.0 * np.log(u1)) * np.cos(_TWO_PI * u2)
