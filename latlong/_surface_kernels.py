"""Numba kernel for :mod:`latlong.surface`: the actual area of every triangle of a run of
latitude bands, the same bits as numpy's
``0.5 * np.linalg.norm(np.cross(p1 - p0, p2 - p0), axis=1)`` over ``Body.vertices``.

Each band's two rings are placed once (``u * (r * stretch)``, the unit vectors of
``_unit_of``) and its triangles zipped as ``LatLongGrid.band_triangles`` does; the cross
product and the norm keep numpy's operation order (no fused multiply-add), so callers
that sum or search the areas get exactly what the numpy expression gave.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ._grid_kernels import _band_triangles_kernel, _ring_size, _unit_of


@njit(cache=True, inline="always")
def _place_ring(m, r, o, n, radii, stretch, out):
    """Positions of ring r's n vertices (first index o) into out[:n]: u * (r * stretch)."""
    for j in range(n):
        x, y, z = _unit_of(m, r, j, n)
        rad = radii[o + j]
        out[j, 0] = x * (rad * stretch[0])
        out[j, 1] = y * (rad * stretch[1])
        out[j, 2] = z * (rad * stretch[2])


@njit(cache=True, inline="always")
def _corner(v, oa, na, pa, pb, ob):
    """Position of vertex v, which lies on ring a (rows of pa) or ring b (rows of pb)."""
    if oa <= v < oa + na:
        return pa[v - oa, 0], pa[v - oa, 1], pa[v - oa, 2]
    return pb[v - ob, 0], pb[v - ob, 1], pb[v - ob, 2]


@njit(cache=True, inline="always")
def _area_of(tri, t, oa, na, pa, pb, ob):
    """Area of triangle row t of ``tri`` whose vertices lie on rings a (pa) and b (pb):
    numpy's cross-product order, then (c0^2 + c1^2) + c2^2 as its norm sums."""
    x0, y0, z0 = _corner(tri[t, 0], oa, na, pa, pb, ob)
    x1, y1, z1 = _corner(tri[t, 1], oa, na, pa, pb, ob)
    x2, y2, z2 = _corner(tri[t, 2], oa, na, pa, pb, ob)
    a0 = x1 - x0
    a1 = y1 - y0
    a2 = z1 - z0
    b0 = x2 - x0
    b1 = y2 - y0
    b2 = z2 - z0
    c0 = a1 * b2 - a2 * b1
    c1 = a2 * b0 - a0 * b2
    c2 = a0 * b1 - a1 * b0
    return 0.5 * np.sqrt((c0 * c0 + c1 * c1) + c2 * c2)


@njit(cache=True, inline="always")
def _band_areas_one(m, band, ring_offsets, radii, stretch, tri, pa, pb, out, t0):
    """Areas of band ``band``'s triangles into out[t0:], with ``tri``, ``pa``, ``pb``
    scratch of at least (na + nb, 3), (na, 3) and (nb, 3) rows. Returns (oa, na, ob,
    triangles): the band's rings as the scratch holds them, for :func:`_corner`."""
    if band < m:
        ra, rb, south = band, band + 1, False
    else:
        ra, rb, south = band + 1, band, True
    oa, na = ring_offsets[ra], _ring_size(ra, m)
    ob, nb = ring_offsets[rb], _ring_size(rb, m)
    _place_ring(m, ra, oa, na, radii, stretch, pa)
    _place_ring(m, rb, ob, nb, radii, stretch, pb)
    _band_triangles_kernel(oa, na, ob, nb, south, tri, np.int64(0))
    n_tri = 6 if (na == 1 or nb == 1) else na + nb
    for t in range(n_tri):
        out[t0 + t] = _area_of(tri, t, oa, na, pa, pb, ob)
    return oa, na, ob, n_tri


@njit(cache=True, parallel=True, nogil=True)
def band_triangle_areas(m, ring_offsets, band_offsets, radii, stretch, band_lo, band_hi,
                        out):
    """Areas (m^2) of the triangles of bands band_lo .. band_hi - 1 into ``out`` (rows
    from band_lo's first triangle), bands in parallel (each writes its own rows)."""
    base = band_offsets[band_lo]
    for band in prange(band_lo, band_hi):
        n = 6 * m + 1
        tri = np.empty((2 * n, 3), dtype=np.int64)
        pa = np.empty((n, 3))
        pb = np.empty((n, 3))
        _band_areas_one(m, band, ring_offsets, radii, stretch, tri, pa, pb, out,
                        band_offsets[band] - base)


@njit(cache=True, nogil=True)
def band_triangle_areas_serial(m, ring_offsets, band_offsets, radii, stretch, band_lo,
                               band_hi, out):
    """:func:`band_triangle_areas` on one thread (a band or a few: a parallel region
    costs more than their work)."""
    base = band_offsets[band_lo]
    n = 6 * m + 1
    tri = np.empty((2 * n, 3), dtype=np.int64)
    pa = np.empty((n, 3))
    pb = np.empty((n, 3))
    for band in range(band_lo, band_hi):
        _band_areas_one(m, band, ring_offsets, radii, stretch, tri, pa, pb, out,
                        band_offsets[band] - base)


@njit(cache=True, inline="always")
def _search_right(cum, n, x):
    """``np.searchsorted(cum[:n], x, side="right")``: how many of cum[:n] are <= x."""
    lo = 0
    hi = n
    while lo < hi:
        mid = (lo + hi) >> 1
        if cum[mid] <= x:
            lo = mid + 1
        else:
            hi = mid
    return lo


@njit(cache=True, parallel=True, nogil=True)
def sample_in_bands(m, ring_offsets, radii, stretch, bands, starts, order, resid, a, b,
                    out):
    """Uniform points in the bands ``bands`` (in parallel): sample ``order[starts[band]:
    starts[band + 1]]`` of band ``band`` takes the triangle where the band's running area
    first exceeds ``resid`` and the point ``v0 + a (v1 - v0) + b (v2 - v0)`` in it, into
    ``out`` rows; numpy's cumsum, searchsorted and operation order (same bits)."""
    n = 6 * m + 1
    for i in prange(bands.shape[0]):
        band = bands[i]
        tri = np.empty((2 * n, 3), dtype=np.int64)
        pa = np.empty((n, 3))
        pb = np.empty((n, 3))
        cum = np.empty(2 * n)
        oa, na, ob, n_tri = _band_areas_one(m, band, ring_offsets, radii, stretch, tri, pa,
                                            pb, cum, 0)
        for t in range(1, n_tri):
            cum[t] = cum[t - 1] + cum[t]
        for s in range(starts[band], starts[band + 1]):
            j = order[s]
            k = min(_search_right(cum, n_tri, resid[j]), n_tri - 1)
            x0, y0, z0 = _corner(tri[k, 0], oa, na, pa, pb, ob)
            x1, y1, z1 = _corner(tri[k, 1], oa, na, pa, pb, ob)
            x2, y2, z2 = _corner(tri[k, 2], oa, na, pa, pb, ob)
            out[j, 0] = (x0 + a[j] * (x1 - x0)) + b[j] * (x2 - x0)
            out[j, 1] = (y0 + a[j] * (y1 - y0)) + b[j] * (y2 - y0)
            out[j, 2] = (z0 + a[j] * (z1 - z0)) + b[j] * (z2 - z0)
