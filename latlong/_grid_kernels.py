"""Numba kernels for the lat/long grid: triangulation and field interpolation."""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from craters.kernels import read_only_inputs

from .geometry._ray_kernels import _moller_trumbore


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


@njit(cache=True, inline="always")
def _one_band(m, band, base, ring_offsets, band_offsets, out):
    t0 = band_offsets[band] - base
    if band < m:  # northern band: inner ring = band, outer = band + 1
        ra, rb, south = band, band + 1, False
    else:  # southern band: inner ring = band + 1 (nearer the south pole)
        ra, rb, south = band + 1, band, True
    _band_triangles_kernel(ring_offsets[ra], _ring_size(ra, m), ring_offsets[rb],
                           _ring_size(rb, m), south, out, t0)


@njit(cache=True, parallel=True)
def _triangles_kernel(m, band_lo, band_hi, ring_offsets, band_offsets, out):
    """Triangles of bands ``band_lo .. band_hi - 1`` into ``out`` (rows from band_lo's),
    bands in parallel (for many triangles: a parallel region costs more than a few
    bands' work)."""
    base = band_offsets[band_lo]
    for band in prange(band_lo, band_hi):
        _one_band(m, band, base, ring_offsets, band_offsets, out)


@njit(cache=True)
def _triangles_serial(m, band_lo, band_hi, ring_offsets, band_offsets, out):
    """:func:`_triangles_kernel` on one thread."""
    base = band_offsets[band_lo]
    for band in range(band_lo, band_hi):
        _one_band(m, band, base, ring_offsets, band_offsets, out)


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


@read_only_inputs("out")
@njit(cache=True, parallel=True)
def _interpolate_kernel(m, ring_offsets, values, colat, lon, out):
    """:func:`_interpolate_one` at many points (parallel)."""
    for p in prange(colat.shape[0]):
        out[p] = _interpolate_one(m, ring_offsets, values, colat[p], lon[p])


@njit(cache=True)
def _zipper_a_steps(na, nb, steps):
    """Ring-a advances among the first ``steps`` zipper steps of a band (closed form).

    The zipper is a stable merge of the a-events k / na (k = 1..na) and the b-events
    l / nb, ties to a: a-event k is step ``k + ceil(k nb / na) - 1`` (1-based), so the
    count is the largest k with that step <= ``steps`` (binary search, O(log na)) - the
    state :func:`_band_triangles_kernel` reaches after replaying ``steps`` steps. A pole
    fan (na = 1) only advances ring b.
    """
    if na == 1:
        return 0
    lo = 0
    hi = na
    while lo < hi:
        mid = (lo + hi + 1) // 2
        if mid + (mid * nb + na - 1) // na - 1 <= steps:
            lo = mid
        else:
            hi = mid - 1
    return lo


@njit(cache=True)
def _band_strip_kernel(oa, na, ob, nb, south, step_lo, step_hi, out):
    """Triangle strip of zipper steps ``step_lo .. step_hi - 1`` of a band into ``out``.

    Every zipper triangle is (current a, current b, new vertex) in the north and
    (current b, current a, new vertex) in the south. A strip appends one vertex per
    triangle; the tail is the current pair, and the step is free when the parity (GL
    winding alternation) matches the kind of advance: an a-advance at even parity with
    the tail (a, b), a b-advance at odd parity with (b, a) (mirrored in the south).
    Otherwise one repeated vertex (a degenerate triangle) flips the parity and the tail
    order together. Alternating advances - most of a band - cost nothing. The zipper
    state at ``step_lo`` is found in closed form (:func:`_zipper_a_steps`). Returns the
    number of vertices written (``out`` needs 2 + 2 * steps entries).
    """
    i = _zipper_a_steps(na, nb, step_lo)
    j = step_lo - i
    steps = na + nb if na > 1 else nb
    a = oa + (i % na)
    b = ob + (j % nb)
    # start in a canonical state: even parity with (a, b) north / (b, a) south
    if south:
        out[0] = b
        out[1] = a
    else:
        out[0] = a
        out[1] = b
    k = 2
    for _ in range(step_lo, min(step_hi, steps)):
        advance_a = na > 1 and i < na and (j >= nb or (i + 1) * nb <= (j + 1) * na)
        parity_even = (k - 2) % 2 == 0
        # north: even parity expects an a-advance; south: even parity expects a b-advance
        expects_a = parity_even != south
        if advance_a != expects_a:
            out[k] = out[k - 2]  # degenerate: flips parity and the tail order
            k += 1
        if advance_a:
            i += 1
            out[k] = oa + (i % na)
        else:
            j += 1
            out[k] = ob + (j % nb)
        k += 1
    return k


@njit(cache=True, nogil=True, parallel=True)
def _lon_table_kernel(m, ring_offsets, out):
    """cos and sin of the longitudes ``2 pi j / n`` of the northern rings 1..M into
    ``out`` (3M(M+1), 2), ring r from row :func:`_lon_row`; a southern ring 2M - r has
    the same n and the same longitudes, so it shares ring r's rows. Ring pairs (r,
    M + 1 - r) per iteration balance the threads."""
    for k in prange((m + 1) // 2):
        for side in range(2):
            r = k + 1 if side == 0 else m - k
            if side == 1 and r == k + 1:
                break
            o = ring_offsets[r] - 1
            n = 6 * r
            for j in range(n):
                lon = 2.0 * np.pi * j / n
                out[o + j, 0] = np.cos(lon)
                out[o + j, 1] = np.sin(lon)


@njit(cache=True, inline="always")
def _lon_row(m, r, ring_offsets):
    """First row of ring r's longitudes (1 <= r <= 2M - 1) in :func:`_lon_table_kernel`'s
    table."""
    r = np.int64(r)  # a prange index may be unsigned: 2m - r must stay an integer
    if r > m:
        r = 2 * np.int64(m) - r
    return ring_offsets[r] - 1


def lon_table(m: int, ring_offsets) -> np.ndarray:
    """:func:`_lon_table_kernel`'s table for a grid of magnitude ``m`` (8 B a vertex)."""
    out = np.empty((3 * m * (m + 1), 2), dtype=np.float64)
    _lon_table_kernel(m, ring_offsets, out)
    return out


@njit(cache=True, inline="always")
def _ring_positions(m, r, o, radii, stretch, table, t0, out):
    """Positions of ring r's vertices (radii times unit vectors, stretched) into out,
    ``stretch * radius * sin(colatitude) * cos(longitude)`` ..., the longitudes'
    cosines and sines from ``table`` rows ``t0 ..`` (:func:`lon_table`), or - ``table``
    empty - computed as :func:`_lon_table_kernel` computes them (the same values)."""
    n = _ring_size(r, m)
    colat = r * (np.pi / (2 * m))
    if n == 1:
        z = 1.0 if r == 0 else -1.0
        out[0, 0] = 0.0
        out[0, 1] = 0.0
        out[0, 2] = stretch[2] * radii[o] * z
        return
    s = np.sin(colat)
    c = np.cos(colat)
    if table.shape[0] == 0:
        for j in range(n):
            lon = 2.0 * np.pi * j / n
            out[j, 0] = stretch[0] * radii[o + j] * s * np.cos(lon)
            out[j, 1] = stretch[1] * radii[o + j] * s * np.sin(lon)
            out[j, 2] = stretch[2] * radii[o + j] * c
        return
    for j in range(n):
        out[j, 0] = stretch[0] * radii[o + j] * s * table[t0 + j, 0]
        out[j, 1] = stretch[1] * radii[o + j] * s * table[t0 + j, 1]
        out[j, 2] = stretch[2] * radii[o + j] * c


@njit(cache=True, inline="always")
def _unit_of(m, r, j, n):
    """Unit vector of vertex j of ring r (n vertices): the one definition used everywhere."""
    if r == 0:
        return 0.0, 0.0, 1.0
    if r == 2 * m:
        return 0.0, 0.0, -1.0
    lat = 0.5 * np.pi - r * (np.pi / (2 * m))
    lon = (2.0 * np.pi * j) / n
    c = np.cos(lat)
    return c * np.cos(lon), c * np.sin(lon), np.sin(lat)


@njit(cache=True, inline="always")
def _rings_of_range(ring_offsets, lo, hi):
    """First and last ring holding vertices ``lo .. hi - 1``."""
    return (np.searchsorted(ring_offsets, lo, side="right") - 1,
            np.searchsorted(ring_offsets, hi - 1, side="right") - 1)


@njit(cache=True, inline="always")
def _ring_part(ring_offsets, lo, hi, r):
    """Ring ``r``'s share of vertices ``lo .. hi - 1``: (its first vertex, its size, the
    first and the end index j on the ring)."""
    o = ring_offsets[r]
    n = ring_offsets[r + 1] - o
    return o, n, max(lo - o, 0), min(hi - o, n)


@njit(cache=True, inline="always")
def _unit_ring(m, ring_offsets, lo, hi, r, out):
    """Unit vectors of ring ``r``'s share of vertices lo..hi-1 into out (hi - lo, 3)."""
    o, n, j0, j1 = _ring_part(ring_offsets, lo, hi, r)
    for j in range(j0, j1):
        x, y, z = _unit_of(m, r, j, n)
        out[o + j - lo, 0] = x
        out[o + j - lo, 1] = y
        out[o + j - lo, 2] = z


@njit(cache=True)
def _unit_range_serial(m, ring_offsets, lo, hi, out):
    """Unit vectors of vertices lo..hi-1 into out (hi - lo, 3) (one thread)."""
    r_first, r_last = _rings_of_range(ring_offsets, lo, hi)
    for r in range(r_first, r_last + 1):
        _unit_ring(m, ring_offsets, lo, hi, r, out)


@njit(cache=True, parallel=True)
def _unit_range_kernel(m, ring_offsets, lo, hi, out):
    """Unit vectors of vertices lo..hi-1 into out (hi - lo, 3), rings in parallel (for
    large ranges: a parallel region costs far more than a small range's work)."""
    r_first, r_last = _rings_of_range(ring_offsets, lo, hi)
    for r in prange(r_first, r_last + 1):
        _unit_ring(m, ring_offsets, lo, hi, r, out)


@njit(cache=True)
def _unit_index_kernel(m, ring_offsets, idx, out):
    """Unit vectors of the vertices ``idx`` (any order) into out (len(idx), 3)."""
    for k in range(idx.shape[0]):
        i = idx[k]
        r = np.searchsorted(ring_offsets, i, side="right") - 1
        o = ring_offsets[r]
        x, y, z = _unit_of(m, r, i - o, ring_offsets[r + 1] - o)
        out[k, 0] = x
        out[k, 1] = y
        out[k, 2] = z


@njit(cache=True, inline="always")
def _vertex_point(m, r, j, ring_offsets, radii, out):
    """Position (radius x unit vector) of vertex j (taken modulo the ring size) of ring r."""
    n = _ring_size(r, m)
    jj = j % n
    colat = r * (np.pi / (2 * m))
    lon = 2.0 * np.pi * jj / n
    rad = radii[ring_offsets[r] + jj]
    s = np.sin(colat)
    out[0] = rad * s * np.cos(lon)
    out[1] = rad * s * np.sin(lon)
    out[2] = rad * np.cos(colat)


@njit(cache=True, inline="always")
def _ray_triangle(dx, dy, dz, a, b, c):
    """Moller-Trumbore for the ray from the origin along d and the triangle (a, b, c),
    two-sided: (u, v, t), the barycentric coordinates of the crossing (b and c weights)
    and its distance along d (in units of |d|); t = -1 when the ray is parallel to the
    triangle. The caller decides what counts as a hit (u, v, 1 - u - v >= 0, t > 0)."""
    t, u, v, det = _moller_trumbore(0.0, 0.0, 0.0, dx, dy, dz, a[0], a[1], a[2], b[0], b[1],
                                    b[2], c[0], c[1], c[2])
    if det == 0.0:
        return np.nan, np.nan, -1.0
    return u, v, t


@njit(cache=True, inline="always")
def _closer_hit(d, p0, p1, p2, best):
    """The ray from the origin along d against triangle (p0, p1, p2), two-sided.

    best = (outside-ness, distance): replaced when this triangle contains the ray
    better (outside-ness = how far the barycentric coordinates leave [0, 1]; <= 0
    inside).
    """
    u, v, t = _ray_triangle(d[0], d[1], d[2], p0, p1, p2)
    if t <= 0.0:
        return
    out = max(-u, -v, u + v - 1.0)
    if out < best[0]:
        best[0] = out
        best[1] = t


@njit(cache=True)
def _surface_radius_one(m, ring_offsets, radii, colat, lon, p0, p1, p2, d, best):
    """Distance from the centre to the flat-triangle mesh along direction (colat, lon).

    The hit triangle lies in one of the three bands around the colatitude (ring edges
    are chords, which bow towards the poles) and near the longitude: each band's zipper
    is replayed from the state entering the b-column before the longitude (the zipper
    enters column j at i = floor(j na / nb)) for three columns.
    """
    d[0] = np.sin(colat) * np.cos(lon)
    d[1] = np.sin(colat) * np.sin(lon)
    d[2] = np.cos(colat)
    s = lon / (2.0 * np.pi)
    s -= np.floor(s)
    best[0] = np.inf
    best[1] = np.nan
    r0 = int(np.floor(colat / (np.pi / (2 * m))))
    for step in range(3):  # the band of the colatitude first, then its neighbours
        band = r0 if step == 0 else (r0 - 1 if step == 1 else r0 + 1)
        if band < 0 or band > 2 * m - 1:
            continue
        if band < m:
            ra, rb = band, band + 1
        else:
            ra, rb = band + 1, band
        na = _ring_size(ra, m)
        nb = _ring_size(rb, m)
        j = int(np.floor(s * nb)) - 1
        if na == 1:
            _vertex_point(m, ra, 0, ring_offsets, radii, p0)
            for k in range(3):
                _vertex_point(m, rb, j + k, ring_offsets, radii, p1)
                _vertex_point(m, rb, j + k + 1, ring_offsets, radii, p2)
                _closer_hit(d, p0, p1, p2, best)
                if best[0] <= 0.0:
                    return best[1]
            continue
        i = (j * na) // nb  # floor division, also for j = -1
        j_end = j + 3
        _vertex_point(m, ra, i, ring_offsets, radii, p0)
        _vertex_point(m, rb, j, ring_offsets, radii, p1)
        while j < j_end:
            if (i + 1) * nb <= (j + 1) * na:
                _vertex_point(m, ra, i + 1, ring_offsets, radii, p2)
                _closer_hit(d, p0, p1, p2, best)
                i += 1
                p0[0], p0[1], p0[2] = p2[0], p2[1], p2[2]
            else:
                _vertex_point(m, rb, j + 1, ring_offsets, radii, p2)
                _closer_hit(d, p0, p1, p2, best)
                j += 1
                p1[0], p1[1], p1[2] = p2[0], p2[1], p2[2]
            if best[0] <= 0.0:  # inside (a hit on a shared edge is the same point)
                return best[1]
    return best[1]


@read_only_inputs("out")
@njit(cache=True, parallel=True)
def _surface_radius_kernel(m, ring_offsets, radii, colat, lon, out):
    """:func:`_surface_radius_one` at many directions (parallel over chunks)."""
    n = colat.shape[0]
    chunk = 4096
    for c in prange((n + chunk - 1) // chunk):
        p0 = np.empty(3)
        p1 = np.empty(3)
        p2 = np.empty(3)
        d = np.empty(3)
        best = np.empty(2)
        for p in range(c * chunk, min(n, (c + 1) * chunk)):
            out[p] = _surface_radius_one(m, ring_offsets, radii, colat[p], lon[p], p0, p1, p2,
                                         d, best)
