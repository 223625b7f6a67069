"""Numba kernels of the glTF export's ring windows (issue 18: exports without whole-body
arrays).

The glTF export needs every vertex's float32 position and unit normal. Holding them for
the whole body costs 24 B a vertex (plus 8 B of longitude table): 16 GB at M = 8192.
These kernels make them for a window of consecutive rings only, with the same values,
bit for bit, as the whole-body kernels (:func:`~latlong._export_kernels._glb_positions_kernel`,
:func:`~latlong.geometry._normal_kernels._normals_from_radii_kernel`): the longitudes' cosines and
sines are computed with the same expression as the table's, and a ring's normal receives
the area vectors of its two bands in the same order (the even band first, each band's
triangles in zipper order), so the export's bytes do not change.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from craters.kernels import read_only_inputs

from .geometry._normal_kernels import _band_area_vectors


@njit(cache=True, inline="always")
def _zigzag(t, n):
    """The ``t``-th of ``0 .. n - 1`` taken from both ends in turn (0, n - 1, 1, n - 2 ...).
    numba gives each thread one contiguous block of a ``prange``, and a window's rings grow
    (or shrink) along it: without this one thread had about three times the other's work
    (an M = 1400 export's window normals 2.15 s against 1.60 s for the whole-body kernel
    over the same bands)."""
    return t // 2 if t % 2 == 0 else n - 1 - t // 2


@read_only_inputs("out")
@njit(cache=True, parallel=True)
def _window_normals_kernel(m, ring_offsets, radii, stretch, no_table, r_lo, r_hi, out, angle):
    """Unit area-weighted (``angle``: angle-weighted) normals (float32) of the vertices of
    rings ``r_lo .. r_hi`` into ``out`` (their count, 3): those of the whole-body kernel,
    bit for bit. The bands
    touching those rings (``r_lo - 1 .. r_hi``) are streamed as the whole-body kernel
    streams them, even bands first, into an accumulator over rings ``r_lo - 1 .. r_hi + 1``
    (the outer two rings only receive part of their bands and are dropped). ``no_table``:
    an empty (0, 2) array (the longitudes computed, the table's values), passed read-only
    so that :func:`_band_area_vectors` compiles once for this kernel and the whole-body
    one."""
    two_m = 2 * m
    a = max(r_lo - 1, 0)
    b = min(r_hi + 1, two_m)
    base = ring_offsets[a]
    acc = np.zeros((ring_offsets[b + 1] - base, 3), dtype=np.float32)
    band_lo = max(r_lo - 1, 0)
    band_hi = min(r_hi, two_m - 1)
    for parity in range(2):
        first = band_lo + ((parity - band_lo) % 2)
        # (a conditional expression as prange's bound made numba run the loop serially)
        count = max((band_hi - first) // 2 + 1, 0)
        for hb in prange(count):  # bands of one parity share no ring: any order, same sums
            _band_area_vectors(m, ring_offsets, radii, stretch, no_table,
                               first + 2 * _zigzag(hb, count), acc, base, angle)
    skip = ring_offsets[r_lo] - base
    for i in prange(out.shape[0]):
        x = np.float64(acc[skip + i, 0])
        y = np.float64(acc[skip + i, 1])
        z = np.float64(acc[skip + i, 2])
        norm = np.sqrt((x * x + y * y) + z * z)
        for c in range(3):
            out[i, c] = acc[skip + i, c]
        if norm > 0:  # as _normalize_rows_kernel
            d = np.float32(norm)
            for c in range(3):
                out[i, c] = out[i, c] / d


@njit(cache=True, parallel=True)
def _window_positions_kernel(m, ring_offsets, radii, stretch, r_lo, r_hi, out):
    """float32 glTF positions of the vertices of rings ``r_lo .. r_hi`` into ``out``:
    :func:`~latlong._export_kernels._glb_positions_kernel`'s values (``(u * r) * s``
    rounded once), the longitudes' cosines and sines computed as the table's are."""
    base = ring_offsets[r_lo]
    n_rings = r_hi - r_lo + 1
    for t in prange(n_rings):
        r = r_lo + _zigzag(t, n_rings)
        o = ring_offsets[r]
        n = ring_offsets[r + 1] - o
        lat = 0.5 * np.pi - r * (np.pi / (2 * m))
        c = np.cos(lat)
        sz = np.sin(lat)
        for j in range(n):
            rad = radii[o + j]
            if r == 0 or r == 2 * m:
                x, y, z = 0.0, 0.0, 1.0 if r == 0 else -1.0
            else:
                lon = 2.0 * np.pi * j / n
                x, y, z = c * np.cos(lon), c * np.sin(lon), sz
            out[o - base + j, 0] = np.float32(x * rad * stretch[0])
            out[o - base + j, 1] = np.float32(y * rad * stretch[1])
            out[o - base + j, 2] = np.float32(z * rad * stretch[2])
