"""Numba kernels for slopes and shading on the lat/long body: vertex normals (from a
vertex array, or streamed band by band from the radii) and cap averages."""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ._grid_kernels import _lon_row, _ring_positions, _ring_size


@njit(cache=True)
def _vertex_normals_kernel(verts, tris, out, area):
    """Add each triangle's area vector (cross product / 2) to its vertices' normals and
    a third of its area to their areas (none when ``area`` is empty), triangle by
    triangle: the one vertex-normal accumulation (``out`` may be float32: each addition
    is done in float64 and stored)."""
    with_area = area.shape[0] > 0
    for t in range(tris.shape[0]):
        a = tris[t, 0]
        b = tris[t, 1]
        c = tris[t, 2]
        e1x = verts[b, 0] - verts[a, 0]
        e1y = verts[b, 1] - verts[a, 1]
        e1z = verts[b, 2] - verts[a, 2]
        e2x = verts[c, 0] - verts[a, 0]
        e2y = verts[c, 1] - verts[a, 1]
        e2z = verts[c, 2] - verts[a, 2]
        nx = 0.5 * (e1y * e2z - e1z * e2y)
        ny = 0.5 * (e1z * e2x - e1x * e2z)
        nz = 0.5 * (e1x * e2y - e1y * e2x)
        third = np.sqrt(nx * nx + ny * ny + nz * nz) / 3.0 if with_area else 0.0
        for v in (a, b, c):
            out[v, 0] += nx
            out[v, 1] += ny
            out[v, 2] += nz
            if with_area:
                area[v] += third


@njit(cache=True, inline="always")
def _add_triangle_normal(pos, a, b, c, out):
    """Add triangle (a, b, c)'s area vector to its vertices' normals: the arithmetic of
    :func:`_vertex_normals_kernel` (without areas), one triangle."""
    e1x = pos[b, 0] - pos[a, 0]
    e1y = pos[b, 1] - pos[a, 1]
    e1z = pos[b, 2] - pos[a, 2]
    e2x = pos[c, 0] - pos[a, 0]
    e2y = pos[c, 1] - pos[a, 1]
    e2z = pos[c, 2] - pos[a, 2]
    nx = 0.5 * (e1y * e2z - e1z * e2y)
    ny = 0.5 * (e1z * e2x - e1x * e2z)
    nz = 0.5 * (e1x * e2y - e1y * e2x)
    for v in (a, b, c):
        out[v, 0] += nx
        out[v, 1] += ny
        out[v, 2] += nz


@njit(cache=True, inline="always")
def _band_normals(pos, oa, na, ob, nb, south, out):
    """Area vectors of a band's triangles, in :func:`_band_triangles_kernel`'s order and
    winding (the same zipper), added to ``out`` as they are made (no triangle array)."""
    if na == 1:  # pole fan
        for j in range(nb):
            if south:
                _add_triangle_normal(pos, oa, ob + (j + 1) % nb, ob + j, out)
            else:
                _add_triangle_normal(pos, oa, ob + j, ob + (j + 1) % nb, out)
        return
    i = 0
    j = 0
    for _ in range(na + nb):
        if i < na and (j >= nb or (i + 1) * nb <= (j + 1) * na):
            p, q, r = oa + i, ob + j % nb, oa + (i + 1) % na
            i += 1
        else:
            p, q, r = oa + i % na, ob + j, ob + (j + 1) % nb
            j += 1
        if south:
            _add_triangle_normal(pos, p, r, q, out)
        else:
            _add_triangle_normal(pos, p, q, r, out)


@njit(cache=True, inline="always")
def _band_area_vectors(m, ring_offsets, radii, stretch, lon_table, band, acc, base):
    """Band ``band``'s two rings positioned locally (:func:`_ring_positions`; longitudes
    from ``lon_table``, or computed when it is empty) and its triangles' area vectors
    added to ``acc`` (row ``v - base`` is vertex v's)."""
    if band < m:
        ra, rb, south = band, band + 1, False
    else:
        ra, rb, south = band + 1, band, True
    na = _ring_size(ra, m)
    nb = _ring_size(rb, m)
    oa = ring_offsets[ra]
    ob = ring_offsets[rb]
    lo = min(oa, ob)
    pos = np.empty((na + nb, 3))
    ta = _lon_row(m, ra, ring_offsets) if lon_table.shape[0] else 0
    tb = _lon_row(m, rb, ring_offsets) if lon_table.shape[0] else 0
    _ring_positions(m, ra, oa, radii, stretch, lon_table, ta, pos[oa - lo:oa - lo + na])
    _ring_positions(m, rb, ob, radii, stretch, lon_table, tb, pos[ob - lo:ob - lo + nb])
    _band_normals(pos, oa - lo, na, ob - lo, nb, south, acc[lo - base:lo - base + na + nb])


@njit(cache=True, parallel=True)
def _normals_from_radii_kernel(m, ring_offsets, band_offsets, radii, stretch, lon_table, acc):
    """Area-weighted vertex normals of the body into ``acc``, streamed band by band (no
    triangle or vertex array of the whole body): each band's two rings (consecutive
    vertex numbers) are positioned locally and its triangles' area vectors added as the
    zipper makes them (:func:`_band_normals`; 40 % less time than triangulating into an
    array first, the same values). Even bands first, then odd bands: the bands of one
    pass share no ring, so they run in parallel and every vertex receives its two bands'
    contributions in a fixed order (deterministic). The longitudes' cosines and sines come
    from ``lon_table`` (:func:`~latlong._grid_kernels.lon_table`)."""
    n_bands = 2 * m
    for parity in range(2):
        for hb in prange((n_bands - parity + 1) // 2):
            band = 2 * hb + parity
            if band >= n_bands:
                continue
            _band_area_vectors(m, ring_offsets, radii, stretch, lon_table, band, acc, 0)


@njit(cache=True, parallel=True)
def _normalize_rows_kernel(acc):
    """Scale the float32 rows of ``acc`` to unit length in place: the norm in float64,
    ``sqrt((x^2 + y^2) + z^2)``, rounded to float32 and divided into each component
    (rows of norm 0 are left alone)."""
    for i in prange(acc.shape[0]):
        x = np.float64(acc[i, 0])
        y = np.float64(acc[i, 1])
        z = np.float64(acc[i, 2])
        norm = np.sqrt((x * x + y * y) + z * z)
        if norm > 0:
            d = np.float32(norm)
            for c in range(3):
                acc[i, c] = acc[i, c] / d


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


@njit(cache=True)
def _scatter_add_kernel(index, values, out):
    """``out[index[t]] += values[t]`` in the order of t (``np.add.at``, (N,) or (N, k))."""
    for t in range(index.shape[0]):
        out[index[t]] += values[t]
