"""Numba kernels of a crater's local frame on the body (split from
:mod:`latlong._crater_kernels`): the candidates' local coordinates and the least-squares
plane and quadric fits of the obliterated region."""

from __future__ import annotations

import numpy as np
from numba import njit

from craters.kernels import PLANE_SUMS0, plane_solve, plane_sums_add


@njit(cache=True, inline="always")
def _stretched(stretch, r, ux, uy, uz):
    """Position ``stretch * r * u`` of radius r along unit vector u, and its length."""
    px = stretch[0] * r * ux
    py = stretch[1] * r * uy
    pz = stretch[2] * r * uz
    return px, py, pz, np.sqrt(px * px + py * py + pz * pz)


@njit(cache=True)
def _fit_plane_points(x, y, h, dist, n, r_fit):
    """Least-squares plane h = p0 + gx x + gy y over the first ``n`` points within r_fit.

    Fewer than 3 points, or a degenerate set: flat at the height of the nearest point.
    """
    s = PLANE_SUMS0
    nearest = 0
    for q in range(n):
        if dist[q] < dist[nearest]:
            nearest = q
        if dist[q] > r_fit:
            continue
        s = plane_sums_add(s, x[q], y[q], h[q])
    spread = s[3] + s[4]  # a determinant's size: n * (sxx + syy)^2
    ok, p0, gx, gy = plane_solve(s, s[0] * spread * spread)
    if ok:
        return p0, gx, gy
    return (h[nearest] if n else 0.0), 0.0, 0.0


@njit(cache=True, inline="always")
def _quadric(p0, gx, gy, qa, qb, qc, x, y):
    return p0 + gx * x + gy * y + qa * x * x + qb * x * y + qc * y * y


@njit(cache=True)
def _cholesky_solve6(a, b, tiny):
    """Solve the symmetric positive definite 6 x 6 system ``a x = b`` in place
    (Cholesky: ``a``'s lower triangle becomes L, ``b`` becomes x); False, leaving
    ``a`` and ``b`` undefined, when a pivot falls to ``tiny`` or below (singular in
    working precision). The normal equations of a least-squares fit are SPD, and
    this costs a fraction of a LAPACK call with its copies."""
    n = 6
    for j in range(n):
        d = a[j, j]
        for k in range(j):
            d -= a[j, k] * a[j, k]
        if not d > tiny:
            return False
        d = np.sqrt(d)
        a[j, j] = d
        for i in range(j + 1, n):
            v = a[i, j]
            for k in range(j):
                v -= a[i, k] * a[j, k]
            a[i, j] = v / d
    for i in range(n):  # L y = b
        v = b[i]
        for k in range(i):
            v -= a[i, k] * b[k]
        b[i] = v / a[i, i]
    for i in range(n - 1, -1, -1):  # L^T x = y
        v = b[i]
        for k in range(i + 1, n):
            v -= a[k, i] * b[k]
        b[i] = v / a[i, i]
    return True


@njit(cache=True)
def _fit_quadric_points(x, y, h, dist, n, r_fit):
    """Least-squares quadric over the points within r_fit (falls back to a plane)."""
    ata = np.zeros((6, 6))
    atb = np.zeros(6)
    row = np.empty(6)
    cnt = 0
    for q in range(n):
        if dist[q] > r_fit:
            continue
        row[0] = 1.0
        row[1] = x[q]
        row[2] = y[q]
        row[3] = x[q] * x[q]
        row[4] = x[q] * y[q]
        row[5] = y[q] * y[q]
        for i in range(6):
            atb[i] += row[i] * h[q]
            for j in range(6):
                ata[i, j] += row[i] * row[j]
        cnt += 1
    if cnt >= 12:
        scale = 0.0
        for i in range(6):
            scale = max(scale, abs(ata[i, i]))
        for i in range(6):
            ata[i, i] += 1e-12 * scale
        if _cholesky_solve6(ata, atb, 1e-15 * scale):
            return atb[0], atb[1], atb[2], atb[3], atb[4], atb[5]
    p0, gx, gy = _fit_plane_points(x, y, h, dist, n, r_fit)
    return p0, gx, gy, 0.0, 0.0, 0.0


@njit(cache=True)
def _local_coordinates(cand, m, ring_offsets, radii, stretch, a0, a1, a2, e0v, e1v, e2v, n0,
                       n1, n2, rloc, reach, limit, idx, pmag, dist, az, xl, yl, hgt):
    """Local coordinates of the candidate vertices ``cand`` around a crater whose centre
    has unit normal ``a`` and east/north axes ``e``, ``n`` at local radius ``rloc``:
    the candidates within arc ``limit`` (metres) are written, in order, to ``idx``
    (vertex), ``pmag`` (|position|), ``dist`` (arc ``rloc`` x angle to the centre),
    ``az`` (azimuth from east; 0 beyond ``reach`` (1 + 1e-12), where the stamp does not
    read it: an arctangent less for a third of the vertices), ``xl, yl`` (dist x (cos,
    sin) az) and ``hgt`` (pmag - rloc). Returns (count written, count within ``reach``)."""
    keep = 0
    az_reach = reach * (1.0 + 1e-12)  # the same bound as _write_range's
    # candidates whose direction is farther than limit / rloc (with a margin far above
    # rounding) are dropped on the dot product alone, before the arctangents
    cos_reject = np.cos(limit / rloc) - 1e-9 if limit / rloc < 3.0 else -2.0
    n_inside = 0
    # candidates come ring by ring (the gather's order): the ring and its latitude's
    # cosine and sine are found once per ring, the same values as _unit_of's
    ring = -1
    o = 0
    n_ring = 1
    clat = 0.0
    slat = 1.0
    prev = -2
    cl = 1.0  # cos and sin of the previous candidate's longitude
    sl = 0.0
    cstep = 1.0  # cos and sin of the ring's longitude step
    sstep = 0.0
    for q in range(cand.shape[0]):
        i = cand[q]
        r = radii[i]
        if ring < 0 or i < o or i >= o + n_ring:
            ring = np.searchsorted(ring_offsets, i, side="right") - 1
            o = ring_offsets[ring]
            n_ring = ring_offsets[ring + 1] - o
            lat_r = 0.5 * np.pi - ring * (np.pi / (2 * m))
            clat = np.cos(lat_r)
            slat = np.sin(lat_r)
            cstep = np.cos(2.0 * np.pi / n_ring)
            sstep = np.sin(2.0 * np.pi / n_ring)
            prev = -2
        if ring == 0:
            ux, uy, uz = 0.0, 0.0, 1.0
        elif ring == 2 * m:
            ux, uy, uz = 0.0, 0.0, -1.0
        else:
            # a ring's candidates come as runs of consecutive vertices: the next
            # longitude by one rotation of the previous (drift ~1e-16 per step) instead
            # of a cosine and a sine per vertex
            if i == prev + 1 and i - o != 0:
                cl, sl = cl * cstep - sl * sstep, sl * cstep + cl * sstep
            else:
                lon_v = (2.0 * np.pi * (i - o)) / n_ring
                cl = np.cos(lon_v)
                sl = np.sin(lon_v)
            prev = i
            ux, uy, uz = clat * cl, clat * sl, slat
        p0v, p1v, p2v, pm = _stretched(stretch, r, ux, uy, uz)
        b0 = p0v / pm
        b1 = p1v / pm
        b2 = p2v / pm
        dot = b0 * a0 + b1 * a1 + b2 * a2
        if dot < cos_reject:
            continue  # certainly beyond ``limit``: the exact test below would drop it
        cx0 = b1 * a2 - b2 * a1
        cx1 = b2 * a0 - b0 * a2
        cx2 = b0 * a1 - b1 * a0
        angle = np.arctan2(np.sqrt(cx0 * cx0 + cx1 * cx1 + cx2 * cx2), dot)
        d = rloc * angle
        if d > limit:
            continue
        yn = b0 * n0 + b1 * n1 + b2 * n2
        xe_ = b0 * e0v + b1 * e1v + b2 * e2v
        rho = np.sqrt(xe_ * xe_ + yn * yn)
        idx[keep] = i
        pmag[keep] = pm
        dist[keep] = d
        az[keep] = np.arctan2(yn, xe_) if d <= az_reach else 0.0
        # d (cos, sin) of the azimuth from its components, not from the angle
        if rho > 0.0:
            xl[keep] = d * (xe_ / rho)
            yl[keep] = d * (yn / rho)
        else:
            xl[keep] = d
            yl[keep] = 0.0
        hgt[keep] = pm - rloc
        keep += 1
        if d <= reach:
            n_inside += 1
    return keep, n_inside
