"""Counter-based random numbers for the dem kernels: splitmix64 keyed by pixel.

A Gaussian deviate is a pure function of ``(key, stream, level, row, col)``: the key
comes from the caller's ``rng`` (drawn once), the stream separates uses (expansion,
gap filling), ``level`` is the expansion level and ``row, col`` the *global* pixel
index at that level. Nothing depends on the order in which pixels are visited, on the
thread count or on how a raster is cut into tiles (DESIGN §3).

Hash: Steele, Lea & Flood's (2014) splitmix64 (``craters.kernels.splitmix64``) chained over
the five integers; the deviate is ``craters.kernels.hash_normal`` of the hash (two 53-bit
uniforms, Box–Muller, cosine branch).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from craters.kernels import hash_normal, splitmix64

STREAM_EXPAND = 1
STREAM_FILL = 2


@njit(cache=True, inline="always")
def _pixel_hash(key, stream, level, row, col):
    """64-bit hash of (key, stream, level, row, col); all arguments are integers."""
    h = splitmix64(np.uint64(key) ^ np.uint64(stream))
    h = splitmix64(h ^ np.uint64(level))
    h = splitmix64(h ^ np.uint64(row))
    return splitmix64(h ^ np.uint64(col))


@njit(cache=True, inline="always")
def _pixel_normal(key, stream, level, row, col):
    """A standard normal deviate determined by (key, stream, level, row, col)."""
    return hash_normal(_pixel_hash(key, stream, level, row, col))


@njit(cache=True)
def _normals_kernel(key, stream, level, rows, cols, out):
    """``out[k] = normal(key, stream, level, rows[k], cols[k])`` (tests, small uses)."""
    for k in range(rows.shape[0]):
        out[k] = _pixel_normal(key, stream, level, rows[k], cols[k])


def key_from_rng(rng) -> tuple[int, int | None]:
    """The 63-bit hash key for ``rng`` (int seed, Generator or None) and the seed to record.

    The key is one draw from ``numpy.random.default_rng(rng)`` (SPEC 7), so the same int
    seed always gives the same key. The recorded seed is the int itself, or None for a
    Generator / fresh entropy (the key is recorded too, which is enough to reproduce).
    """
    from craters._shared import normalize_rng

    gen = normalize_rng(rng)  # validates ``rng``
    seed = None if rng is None or isinstance(rng, np.random.Generator) else int(rng)
    return int(gen.integers(0, 2**63, dtype=np.int64)), seed
