"""Numba kernels for slopes on the lat/long body and on meshes: per-ring prefix sums and
cap averages over the grid, and cap sums over vertex directions (the vertex normals
they average are :mod:`latlong.geometry.normals`')."""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ._grid_kernels import _ring_size


@njit(cache=True, parallel=True)
def _ring_prefix_kernel(ring_offsets, values, out):
    """Per-ring prefix sums of ``values`` (N, k) into ``out`` (N + rings, k).

    Ring r's prefix occupies rows ring_offsets[r] + r .. ring_offsets[r+1] + r, the first
    being zero, so the sum of positions [j0, j1) is out[o + r + j1] - out[o + r + j0].
    """
    n_rings = ring_offsets.shape[0] - 1
    k = values.shape[1]
    for r in prange(n_rings):
        o = ring_offsets[r]
        n = ring_offsets[r + 1] - o
        base = o + r
        for c in range(k):
            out[base, c] = 0.0
        for j in range(n):
            for c in range(k):
                out[base + j + 1, c] = out[base + j, c] + values[o + j, c]


@njit(cache=True, inline="always")
def _arc_sum(prefix, base, n, jlo, jhi, c):
    """Sum of ring positions jlo..jhi (inclusive, may wrap; jhi - jlo + 1 <= n)."""
    lo = jlo % n
    count = jhi - jlo + 1
    hi = lo + count
    if hi <= n:
        return prefix[base + hi, c] - prefix[base + lo, c]
    return (prefix[base + n, c] - prefix[base + lo, c]) + (prefix[base + hi - n, c]
                                                          - prefix[base, c])


@njit(cache=True, parallel=True)
def _cap_average_kernel(m, ring_offsets, prefix, ang, out):
    """Sum over every vertex's cap of angular radius ``ang`` (parameter directions).

    For a vertex, the rings the cap crosses are visited and on each the arc of
    longitudes inside it is summed from the ring's prefix sums: O(rings in the cap) per
    vertex, whatever the number of vertices in the cap. The arc's half-width depends
    only on the two rings (closed form: cos(dlon) >= (cos a - cos t cos t') / (sin t
    sin t')), so it is computed once per ring pair, not per vertex.
    """
    step = np.pi / (2 * m)
    cos_a = np.cos(ang)
    k = prefix.shape[1]
    n_rings = 2 * m + 1
    span = int(np.ceil(ang / step - 1e-9)) + 1
    for rv in prange(n_rings):
        nv = _ring_size(rv, m)
        ov = ring_offsets[rv]
        th = rv * step
        ct = np.cos(th)
        st = np.sin(th)
        r_lo = max(0, rv - span)
        r_hi = min(2 * m, rv + span)
        # per target ring: -1 = not crossed, 2 = whole ring, else half-width of the arc
        half = np.empty(r_hi - r_lo + 1)
        for r in range(r_lo, r_hi + 1):
            theta = r * step
            if abs(theta - th) > ang + 1e-12:
                half[r - r_lo] = -1.0
                continue
            n = _ring_size(r, m)
            den = np.sin(theta) * st
            if n == 1 or den < 1e-15:
                half[r - r_lo] = 2.0 * np.pi
                continue
            cc = (cos_a - np.cos(theta) * ct) / den
            if cc > 1.0:
                half[r - r_lo] = -1.0
            elif cc <= -1.0:
                half[r - r_lo] = 2.0 * np.pi
            else:
                half[r - r_lo] = np.arccos(cc)
        for j in range(nv):
            i = ov + j
            lon = 2.0 * np.pi * j / nv
            for c in range(k):
                out[i, c] = 0.0
            for r in range(r_lo, r_hi + 1):
                dl = half[r - r_lo]
                if dl < 0.0:
                    continue
                n = _ring_size(r, m)
                base = ring_offsets[r] + r
                if dl >= np.pi or n == 1:
                    for c in range(k):
                        out[i, c] += prefix[base + n, c] - prefix[base, c]
                    continue
                scale = n / (2.0 * np.pi)
                jlo = int(np.ceil((lon - dl) * scale - 1e-9))
                jhi = int(np.floor((lon + dl) * scale + 1e-9))
                if jhi < jlo:
                    continue
                if jhi - jlo + 1 > n:
                    jlo = 0
                    jhi = n - 1
                for c in range(k):
                    out[i, c] += _arc_sum(prefix, base, n, jlo, jhi, c)



@njit(cache=True, inline="always")
def _box_gap(p, lo, side):
    """Smallest and largest distance (1-D) from ``p`` to the interval [lo, lo + side]."""
    hi = lo + side
    near = lo - p if p < lo else (p - hi if p > hi else 0.0)
    far = max(abs(p - lo), abs(p - hi))
    return near, far


@njit(cache=True, parallel=True)
def _direction_cap_sum_kernel(dirs, values, cells, keys, starts, cell_sums, nc, side, reach,
                              chord2, out):
    """Sum of ``values`` over every point's cap: the points whose unit direction lies
    within the chord ``sqrt(chord2)`` of its own (``|d_j - d_i|^2 <= chord2``).

    Points are sorted by cell of a cubic grid over [-1, 1]^3 (``nc`` cells a side of
    ``side`` >= chord / ``reach``): ``cells`` (N, 3) each point's cell, ``keys`` the sorted
    distinct cell keys ``(ix nc + iy) nc + iz``, ``starts`` their first points (plus N)
    and ``cell_sums`` their sums of ``values``. Each point visits the cells within
    ``reach`` of its own (one binary search per column: a column's cells are consecutive
    keys): a cell wholly outside the cap is skipped, one wholly inside adds its sum, the
    others are tested point by point. Memory O(N); every sum in a fixed order (thread-count
    independent).
    """
    n = dirs.shape[0]
    k = values.shape[1]
    n_keys = keys.shape[0]
    for i in prange(n):
        acc = np.zeros(k)
        px = dirs[i, 0]
        py = dirs[i, 1]
        pz = dirs[i, 2]
        for dx in range(-reach, reach + 1):
            cx = cells[i, 0] + dx
            if cx < 0 or cx >= nc:
                continue
            nx, fx = _box_gap(px, cx * side - 1.0, side)
            for dy in range(-reach, reach + 1):
                cy = cells[i, 1] + dy
                if cy < 0 or cy >= nc:
                    continue
                ny, fy = _box_gap(py, cy * side - 1.0, side)
                if nx * nx + ny * ny > chord2:
                    continue
                base = (cx * nc + cy) * nc
                z_hi = base + min(cells[i, 2] + reach, nc - 1)
                s = np.searchsorted(keys, base + max(cells[i, 2] - reach, 0))
                while s < n_keys and keys[s] <= z_hi:
                    nz, fz = _box_gap(pz, (keys[s] - base) * side - 1.0, side)
                    if nx * nx + ny * ny + nz * nz > chord2:
                        s += 1
                        continue
                    if fx * fx + fy * fy + fz * fz <= chord2:
                        for c in range(k):
                            acc[c] += cell_sums[s, c]
                        s += 1
                        continue
                    for j in range(starts[s], starts[s + 1]):
                        ex = dirs[j, 0] - px
                        ey = dirs[j, 1] - py
                        ez = dirs[j, 2] - pz
                        if ex * ex + ey * ey + ez * ez <= chord2:
                            for c in range(k):
                                acc[c] += values[j, c]
                    s += 1
        for c in range(k):
            out[i, c] = acc[c]
