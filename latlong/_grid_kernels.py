"""Numba kernels for the lat/long grid: triangulation and field interpolation."""

from __future__ import annotations

import numpy as np
from numba import njit, prange


@njit(cache=True)
def _ring_size(r, m):
    """Number of vertices on global ring ``r`` (0 = north pole, 2m = south pole)."""
    if r == 0 or r == 2 * m:
        return 1
    return 6 * min(r, 2 * m - r)


@njit(cache=True, inline="always")
def _emit(out, t, p, q, r, south):
    """Write triangle (p, q, r) as given in the north, mirrored (p, r, q) in the south."""
    out[t, 0] = p
    if south:
        out[t, 1] = r
        out[t, 2] = q
    else:
        out[t, 1] = q
        out[t, 2] = r


@njit(cache=True)
def _band_triangles_kernel(oa, na, ob, nb, south, out, t0):
    """Zip the band between inner ring a (nearer a pole) and outer ring b into ``out``.

    Both rings start at longitude 0 and are walked by increasing longitude; the vertex
    whose next longitude comes first advances (ties advance ring a, which gives
    the shorter diagonal next to the sector boundaries). Writes na + nb triangles (6 for
    a pole fan) starting at row ``t0``, counter-clockwise seen from outside.
    """
    t = t0
    if na == 1:  # pole fan
        for j in range(nb):
            _emit(out, t, oa, ob + j, ob + (j + 1) % nb, south)
            t += 1
        return
    i = 0
    j = 0
    for _ in range(na + nb):
        if i < na and (j >= nb or (i + 1) * nb <= (j + 1) * na):
            _emit(out, t, oa + i, ob + j % nb, oa + (i + 1) % na, south)
            i += 1
        else:
            _emit(out, t, oa + i % na, ob + j, ob + (j + 1) % nb, south)
            j += 1
        t += 1


@njit(cache=True, parallel=True)
def _triangles_kernel(m, band_lo, band_hi, ring_offsets, band_offsets, out):
    """Triangles of bands ``band_lo .. band_hi - 1`` into ``out`` (rows from band_lo's)."""
    base = band_offsets[band_lo]
    for band in prange(band_lo, band_hi):
        t0 = band_offsets[band] - base
        if band < m:  # northern band: inner ring = band, outer = band + 1
            ra, rb, south = band, band + 1, False
        else:  # southern band: inner ring = band + 1 (nearer the south pole)
            ra, rb, south = band + 1, band, True
        _band_triangles_kernel(ring_offsets[ra], _ring_size(ra, m), ring_offsets[rb],
                               _ring_size(rb, m), south, out, t0)


@njit(cache=True)
def _interpolate_one(m, ring_offsets, values, colat, lon):
    """Ring-bilinear interpolation of a grid-``m`` field at one (colat, lon).

    Rings are equally spaced in colatitude (pi / (2m)); along a ring values are linear in
    longitude with wrap-around; between the two rings the results are blended linearly.
    """
    n_rings = 2 * m + 1
    q = colat / (np.pi / (2 * m))
    r0 = int(np.floor(q))
    if r0 < 0:
        r0 = 0
    if r0 > n_rings - 2:
        r0 = n_rings - 2
    t = q - r0
    if t < 0.0:
        t = 0.0
    elif t > 1.0:
        t = 1.0
    acc = 0.0
    for k in range(2):
        r = r0 + k
        n = _ring_size(r, m)
        if n == 1:
            v = values[ring_offsets[r]]
        else:
            s = (lon / (2.0 * np.pi)) * n
            s = s - np.floor(s / n) * n
            j0 = int(np.floor(s))
            w = s - j0
            if j0 >= n:
                j0 = n - 1
                w = 1.0
            j1 = j0 + 1
            if j1 == n:
                j1 = 0
            v = (1.0 - w) * values[ring_offsets[r] + j0] + w * values[ring_offsets[r] + j1]
        acc += (1.0 - t) * v if k == 0 else t * v
    return acc


@njit(cache=True, parallel=True)
def _interpolate_kernel(m, ring_offsets, values, colat, lon, out):
    """:func:`_interpolate_one` at many points (parallel)."""
    for p in prange(colat.shape[0]):
        out[p] = _interpolate_one(m, ring_offsets, values, colat[p], lon[p])
