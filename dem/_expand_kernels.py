"""Numba kernel for one random-midpoint-displacement (diamond-square) doubling."""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from craters.kernels import bilinear, read_only_inputs

from ._rng_kernels import STREAM_EXPAND, _pixel_normal

# the four axis neighbours of a diamond-phase pixel
_DI = np.array([-1, 1, 0, 0], dtype=np.int64)
_DJ = np.array([0, 0, -1, 1], dtype=np.int64)


@njit(cache=True, inline="always")
def _amplitude(amp, y, x):
    """Bilinear interpolation of ``amp`` at fractional index (y, x), clamped to its edges."""
    n_r, n_c = amp.shape
    if y <= 0.0:
        y = 0.0
    elif y >= n_r - 1:
        y = n_r - 1.0
    if x <= 0.0:
        x = 0.0
    elif x >= n_c - 1:
        x = n_c - 1.0
    return bilinear(amp, y, x, False)


@njit(cache=True, inline="always")
def _displace(total, n, sd, amp, amp_row0, amp_col0, inv_scale, key, level, row, col):
    """Mean ``total / n`` (NaN if n = 0) plus the Gaussian of lattice pixel (row, col)
    times ``sd`` times the local amplitude."""
    if n == 0:
        return np.nan
    mean = total / n
    if sd == 0.0:
        return mean
    a = _amplitude(amp, row * inv_scale - amp_row0, col * inv_scale - amp_col0)
    if a == 0.0:
        return mean
    return mean + sd * a * _pixel_normal(key, STREAM_EXPAND, level, row, col)


@read_only_inputs("out")
@njit(cache=True, parallel=True)
def _expand_kernel(old, key, level, row0, col0, sd_square, sd_diamond, amp, amp_row0,
                   amp_col0, inv_scale, out):
    """Double ``old`` (rows, cols) into ``out`` (2 rows - 1, 2 cols - 1).

    Even pixels ``out[2i, 2j] = old[i, j]``; square phase: each (odd, odd) pixel is the
    mean of its four diagonal old pixels; diamond phase: each pixel with one odd index
    is the mean of its (up to) four axis neighbours (two old, two from the square phase;
    three on the border). NaN neighbours are skipped (NaN if none is known). Each new
    pixel is displaced by ``sd_square`` / ``sd_diamond`` times the local amplitude times
    a Gaussian. ``out[i, j]`` is lattice pixel ``(row0 + i, col0 + j)`` of ``level``;
    its amplitude is ``amp`` (metres, on the input grid whose pixel (0, 0) is lattice
    pixel ``(amp_row0, amp_col0)`` there) interpolated bilinearly at
    ``(row0 + i) * inv_scale``; its Gaussian is keyed by ``(key, level, row0 + i,
    col0 + j)``, so rows run in parallel and nothing depends on the thread count.
    """
    rows, cols = old.shape
    n_r = 2 * rows - 1
    n_c = 2 * cols - 1
    for i in prange(rows):
        for j in range(cols):
            out[2 * i, 2 * j] = old[i, j]
    for k in prange(rows - 1):
        i = 2 * k + 1
        for m in range(cols - 1):
            j = 2 * m + 1
            s = 0.0
            n = 0
            for a in range(2):
                for b in range(2):
                    v = old[k + a, m + b]
                    if v == v:
                        s += v
                        n += 1
            out[i, j] = _displace(s, n, sd_square, amp, amp_row0, amp_col0, inv_scale, key,
                                  level, row0 + i, col0 + j)
    for i in prange(n_r):
        for j in range(1 - (i & 1), n_c, 2):
            s = 0.0
            n = 0
            for d in range(4):
                ii = i + _DI[d]
                jj = j + _DJ[d]
                if 0 <= ii < n_r and 0 <= jj < n_c:
                    v = out[ii, jj]
                    if v == v:
                        s += v
                        n += 1
            out[i, j] = _displace(s, n, sd_diamond, amp, amp_row0, amp_col0, inv_scale, key,
                                  level, row0 + i, col0 + j)
