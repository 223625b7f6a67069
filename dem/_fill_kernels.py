"""Numba kernel for outside-in fractal gap filling (Martin et al., lunar paper IV.B)."""

from __future__ import annotations

import numpy as np
from numba import njit

from craters.kernels import DC8, DR8, idw8

from ._rng_kernels import STREAM_FILL, _pixel_normal


@njit(cache=True)
def _fill_gaps_kernel(z, key, level, row0, col0, sigma, step_len, order):
    """Fill the NaN pixels of ``z`` in place, outside in, in waves; return the wave count.

    Each wave takes *all* unknown pixels that have the most known 8-neighbours at that
    moment and fills them at once from the pixels known before the wave: the
    inverse-distance average of the nearest known pixel along each of the 8 directions
    (distances ``k * step_len[d]``) plus ``sigma`` times the Gaussian keyed by
    ``(key, level, row0 + r, col0 + c)``. Then the neighbour counts are updated and the
    next wave starts. Bucket lists (one per count, stale entries skipped) keep the work
    proportional to the number of unknown pixels plus the ray lengths. ``order`` (one
    int32 per pixel) receives each filled pixel's wave number (-1 for known pixels).
    """
    rows, cols = z.shape
    known = np.empty((rows, cols), dtype=np.bool_)
    n_unknown = 0
    for r in range(rows):
        for c in range(cols):
            k = z[r, c] == z[r, c]
            known[r, c] = k
            order[r, c] = -1
            if not k:
                n_unknown += 1
    if n_unknown == 0:
        return 0
    count = np.zeros((rows, cols), dtype=np.int64)
    cap = 9 * n_unknown + 1
    ent_pix = np.empty(cap, dtype=np.int64)
    ent_next = np.empty(cap, dtype=np.int64)
    head = np.full(9, -1, dtype=np.int64)
    n_ent = 0
    for r in range(rows):
        for c in range(cols):
            if known[r, c]:
                continue
            n = 0
            for d in range(8):
                rr = r + DR8[d]
                cc = c + DC8[d]
                if 0 <= rr < rows and 0 <= cc < cols and known[rr, cc]:
                    n += 1
            count[r, c] = n
            ent_pix[n_ent] = r * cols + c
            ent_next[n_ent] = head[n]
            head[n] = n_ent
            n_ent += 1
    wave = np.empty(n_unknown, dtype=np.int64)
    vals = np.empty(n_unknown, dtype=np.float64)
    remaining = n_unknown
    n_wave = 0
    while remaining > 0:
        size = 0
        b = 8
        while b >= 0 and size == 0:
            e = head[b]
            head[b] = -1
            while e >= 0:
                p = ent_pix[e]
                r = p // cols
                c = p - r * cols
                if not known[r, c] and count[r, c] == b:
                    wave[size] = p
                    size += 1
                e = ent_next[e]
            b -= 1
        if size == 0:  # cannot happen while a known pixel exists
            break
        for t in range(size):
            p = wave[t]
            r = p // cols
            c = p - r * cols
            v = idw8(z, known, r, c, step_len, np.nan)
            if sigma > 0.0:
                v += sigma * _pixel_normal(key, STREAM_FILL, level, row0 + r, col0 + c)
            vals[t] = v
        for t in range(size):
            p = wave[t]
            r = p // cols
            c = p - r * cols
            z[r, c] = vals[t]
            known[r, c] = True
            order[r, c] = n_wave
        for t in range(size):
            p = wave[t]
            r = p // cols
            c = p - r * cols
            for d in range(8):
                rr = r + DR8[d]
                cc = c + DC8[d]
                if 0 <= rr < rows and 0 <= cc < cols and not known[rr, cc]:
                    n = count[rr, cc] + 1
                    count[rr, cc] = n
                    ent_pix[n_ent] = rr * cols + cc
                    ent_next[n_ent] = head[n]
                    head[n] = n_ent
                    n_ent += 1
        remaining -= size
        n_wave += 1
    return n_wave
