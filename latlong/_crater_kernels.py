"""Numba kernels for stamping craters on the lat/long body via local DEM mapping."""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from craters.kernels import (
    DC8,
    DR8,
    PLANE_SUMS0,
    fbm2,
    idw8,
    outer_weight,
    plane_solve,
    plane_sums_add,
    rim_offsets,
    roughness_amp,
    roughness_octaves,
    slope_factor,
    table,
    table_value,
)

from ._grid_kernels import _interpolate_one, _ring_size


@njit(cache=True)
def _gather_kernel(m, ring_offsets, colat_c, lon_c, ang, out, count_only):
    """Vertices within angle ``ang`` (radians, parameter space) of a direction.

    Visits only the rings that the cap crosses and, on each, the arc of longitudes
    inside it (closed form, one vertex of margin on each side): O(vertices + rings).
    Writes indices into ``out`` unless ``count_only``; returns the count.
    """
    step = np.pi / (2 * m)
    r_lo = max(0, int(np.floor((colat_c - ang) / step)) - 1)
    r_hi = min(2 * m, int(np.ceil((colat_c + ang) / step)) + 1)
    cos_a = np.cos(ang)
    cc = np.cos(colat_c)
    sc = np.sin(colat_c)
    k = 0
    for r in range(r_lo, r_hi + 1):
        n = _ring_size(r, m)
        o = ring_offsets[r]
        theta = r * step
        if n == 1:
            if abs(theta - colat_c) <= ang + step:
                if not count_only:
                    out[k] = o
                k += 1
            continue
        den = np.sin(theta) * sc
        if den < 1e-12:
            full = abs(theta - colat_c) <= ang + step
            if not full:
                continue
            c = -2.0
        else:
            c = (cos_a - np.cos(theta) * cc) / den
        if c > 1.0:
            # the cap misses this ring's centre line; keep the nearest vertices as margin
            c = 1.0
        if c <= -1.0:
            jlo = 0
            jhi = n - 1
        else:
            dl = np.arccos(c)
            jlo = int(np.floor((lon_c - dl) * n / (2.0 * np.pi))) - 1
            jhi = int(np.ceil((lon_c + dl) * n / (2.0 * np.pi))) + 1
            if jhi - jlo + 1 > n:
                jlo = 0
                jhi = n - 1
        for j in range(jlo, jhi + 1):
            if not count_only:
                out[k] = o + j % n
            k += 1
    return k


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
def _scan_all(unit, c0, c1, c2, cos_ang):
    """The naive gather (benchmark reference): test every vertex of the body."""
    n = unit.shape[0]
    hit = np.empty(n, np.int64)
    k = 0
    for i in range(n):
        if unit[i, 0] * c0 + unit[i, 1] * c1 + unit[i, 2] * c2 >= cos_ang:
            hit[k] = i
            k += 1
    return hit[:k]


# length of one step along each of the 8 directions of ``idw8``, in cells
_STEP8 = np.sqrt((DR8 * DR8 + DC8 * DC8).astype(np.float64))


@njit(cache=True)
def _known_mean(grid, known):
    """Mean of the known cells of a square grid (0 if none), row by row."""
    g = grid.shape[0]
    total = 0.0
    n_known = 0
    for i in range(g):
        for j in range(g):
            if known[i, j]:
                total += grid[i, j]
                n_known += 1
    return total / n_known if n_known else 0.0


@njit(cache=True)
def _fill_holes(grid, known):
    """Fill unknown cells by the inverse-distance average of the nearest known cell in
    each of the 8 directions; cells that see none get the mean of the known cells."""
    g = grid.shape[0]
    mean = _known_mean(grid, known)
    out = grid.copy()
    for i in range(g):
        for j in range(g):
            if not known[i, j]:
                out[i, j] = idw8(grid, known, i, j, _STEP8, mean)
    return out


@njit(cache=True)
def _fill_rim_cells(grid, known, cy, cx, pixel, radius, rim_tab):
    """:func:`_fill_holes` only for the cells that the rim offsets' bilinear samples read
    (the same samples as ``rim_offsets``; each filled cell gets the same value as there,
    the other unknown cells are left as they are): the rim needs a ring of cells, not
    the whole grid."""
    g = grid.shape[0]
    mean = _known_mean(grid, known)
    out = grid.copy()
    done = known.copy()
    n = rim_tab.shape[0]
    for k in range(n):
        theta = -np.pi + 2.0 * np.pi * k / n
        r = radius * (1.0 + rim_tab[k])
        fy = cy + r * np.sin(theta) / pixel
        fx = cx + r * np.cos(theta) / pixel
        if not (0.0 <= fy <= g - 1 and 0.0 <= fx <= g - 1):
            continue
        i0 = min(int(fy), g - 2) if g > 1 else 0
        j0 = min(int(fx), g - 2) if g > 1 else 0
        for i in (i0, min(i0 + 1, g - 1)):
            for j in (j0, min(j0 + 1, g - 1)):
                if not done[i, j]:
                    out[i, j] = idw8(grid, known, i, j, _STEP8, mean)
                    done[i, j] = True
    return out


@njit(cache=True, inline="always")
def _stretched(stretch, r, ux, uy, uz):
    """Position ``stretch * r * u`` of radius r along unit vector u, and its length."""
    px = stretch[0] * r * ux
    py = stretch[1] * r * uy
    pz = stretch[2] * r * uz
    return px, py, pz, np.sqrt(px * px + py * py + pz * pz)


# vertices above which a crater is written in parallel: a parallel region costs tens of
# microseconds, far more when the other core is busy, so small craters stay serial
PARALLEL_MIN = 20_000


@njit(cache=True)
def _write_range(lo, hi, radii, idx, pmag, dist, az, xl, yl, hgt, radius, tab, scale, depth, xe,
                 rim_tab, delta, p0, gx, gy, qa, qb, qc, rough, seed, wavelength, octaves, gain,
                 dh_out):
    """New radii for gathered vertices lo..hi-1 (each vertex written once)."""
    for q in range(lo, hi):
        x = dist[q] / (radius * (1.0 + table(rim_tab, az[q])))
        dh = 0.0
        if x < xe:
            if x <= 1.0:
                new = (_quadric(p0, gx, gy, qa, qb, qc, xl[q], yl[q])
                       + scale * table_value(tab, x, xe))
            else:
                new = (hgt[q] + scale * table_value(tab, x, xe)
                       + table(delta, az[q]) * outer_weight(x, xe))
            if rough[0] > 0.0 or rough[1] > 0.0 or rough[2] > 0.0:
                amp = roughness_amp(x, xe, rough[0], rough[1], rough[2]) * depth * scale
                new += amp * fbm2(seed, xl[q], yl[q], wavelength, octaves, gain)
            dh = new - hgt[q]
            i = idx[q]
            radii[i] = radii[i] * (pmag[q] + dh) / pmag[q]
        dh_out[q] = dh


@njit(cache=True, parallel=True)
def _write_parallel(radii, idx, pmag, dist, az, xl, yl, hgt, radius, tab, scale, depth, xe,
                    rim_tab, delta, p0, gx, gy, qa, qb, qc, rough, seed, wavelength, octaves,
                    gain, dh_out):
    """:func:`_write_range` over blocks of vertices in parallel (blocks are disjoint)."""
    n = idx.shape[0]
    block = 4096
    for b in prange((n + block - 1) // block):
        _write_range(b * block, min(n, (b + 1) * block), radii, idx, pmag, dist, az, xl, yl,
                     hgt, radius, tab, scale, depth, xe, rim_tab, delta, p0, gx, gy, qa, qb,
                     qc, rough, seed, wavelength, octaves, gain, dh_out)


@njit(cache=True)
def _local_coordinates(cand, m, ring_offsets, radii, stretch, a0, a1, a2, e0v, e1v, e2v, n0,
                       n1, n2, rloc, reach, limit, idx, pmag, dist, az, xl, yl, hgt):
    """Local coordinates of the candidate vertices ``cand`` around a crater whose centre
    has unit normal ``a`` and east/north axes ``e``, ``n`` at local radius ``rloc``:
    the candidates within arc ``limit`` (metres) are written, in order, to ``idx``
    (vertex), ``pmag`` (|position|), ``dist`` (arc ``rloc`` x angle to the centre),
    ``az`` (azimuth from east), ``xl, yl`` (dist x (cos, sin) az) and ``hgt`` (pmag -
    rloc). Returns (count written, count within ``reach``)."""
    keep = 0
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
        az[keep] = np.arctan2(yn, xe_)
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


@njit(cache=True)
def _stamp_one(c, m, ring_offsets, unit, radii, stretch, lat, lon, diam, tabs, depths, rim_tabs,
               seeds, xe, slope_erosion, onset_deg, full_deg, rough, gain, out_scale, out_slope,
               out_centre, out_maxdh, out_nvert, out_spacing, out_erased, up, naive, stop_after,
               inner_parallel, ang_bound):
    """Stamp crater ``c`` (see :func:`_stamp_body_kernel`); False, with nothing written,
    when its gather cap would exceed ``ang_bound`` (radians: the wave schedule's bound)."""
    smax = max(stretch[0], max(stretch[1], stretch[2]))
    smin = min(stretch[0], min(stretch[1], stretch[2]))
    n_rim = rim_tabs.shape[1]
    delta = np.empty(n_rim)
    la = np.radians(lat[c])
    lo = np.radians(lon[c])
    colat = 0.5 * np.pi - la
    uc0 = np.cos(la) * np.cos(lo)
    uc1 = np.cos(la) * np.sin(lo)
    uc2 = np.sin(la)
    rc = _interpolate_one(m, ring_offsets, radii, colat, lo)
    pc0, pc1, pc2, rloc = _stretched(stretch, rc, uc0, uc1, uc2)
    a0 = pc0 / rloc
    a1 = pc1 / rloc
    a2 = pc2 / rloc
    # east = z x a, north = a x east (x axis as east at the poles)
    e0v = -a1
    e1v = a0
    e2v = 0.0
    en = np.sqrt(e0v * e0v + e1v * e1v)
    if en < 1e-12:
        e0v, e1v, e2v = 1.0, 0.0, 0.0
    else:
        e0v /= en
        e1v /= en
    n0 = a1 * e2v - a2 * e1v
    n1 = a2 * e0v - a0 * e2v
    n2 = a0 * e1v - a1 * e0v
    radius = 0.5 * diam[c]
    rho_max = 0.0
    for k in range(n_rim):
        rho_max = max(rho_max, rim_tabs[c, k])
    reach = xe * radius * (1.0 + rho_max)
    nominal = rloc * np.pi / (2 * m)
    ang = min(np.pi, (reach + 2.0 * nominal) / rloc * smax / smin)
    if ang > ang_bound:
        return False  # the surface moved more than the wave schedule allowed for
    if naive:
        cand = _scan_all(unit, uc0, uc1, uc2, np.cos(ang))
        cnt = cand.shape[0]
    else:
        cnt = _gather_kernel(m, ring_offsets, colat, lo, ang, np.empty(0, np.int64), True)
        cand = np.empty(cnt, np.int64)
        _gather_kernel(m, ring_offsets, colat, lo, ang, cand, False)
    # local coordinates of the candidates
    idx = np.empty(cnt, np.int64)
    pmag = np.empty(cnt)
    dist = np.empty(cnt)
    az = np.empty(cnt)
    xl = np.empty(cnt)
    yl = np.empty(cnt)
    hgt = np.empty(cnt)
    limit = reach + 2.0 * nominal
    keep, n_inside = _local_coordinates(cand, m, ring_offsets, radii, stretch, a0, a1, a2,
                                        e0v, e1v, e2v, n0, n1, n2, rloc, reach, limit, idx,
                                        pmag, dist, az, xl, yl, hgt)
    if stop_after == 1:
        return True
    # local vertex spacing from the vertex density inside the reach
    if n_inside >= 4:
        sp = np.sqrt(np.pi * reach * reach / n_inside)
    else:
        sp = max(nominal, 0.5 * reach)
    # the plane of the obliterated region, fitted to the vertices' true local
    # coordinates (at least 2 spacings across, so that craters of a few vertex
    # spacings still get the local tilt: radial heights on a stretched body are
    # tilted even where the surface is smooth)
    p0, gx, gy, qa, qb, qc = _fit_quadric_points(xl, yl, hgt, dist, keep,
                                                max(radius, 2.0 * sp))
    # the local grid holds the terrain relative to that plane (binned at the local
    # vertex spacing, holes filled), from which the rim offsets are sampled
    nh = int(np.ceil(limit / sp)) + 1
    g = 2 * nh + 1
    acc = np.zeros((g, g))
    num = np.zeros((g, g))
    for q in range(keep):
        gi = int(np.round(yl[q] / sp)) + nh
        gj = int(np.round(xl[q] / sp)) + nh
        if 0 <= gi < g and 0 <= gj < g:
            acc[gi, gj] += hgt[q] - _quadric(p0, gx, gy, qa, qb, qc, xl[q], yl[q])
            num[gi, gj] += 1.0
    known = num > 0
    for gi in range(g):
        for gj in range(g):
            if known[gi, gj]:
                acc[gi, gj] /= num[gi, gj]
    local = _fill_rim_cells(acc, known, float(nh), float(nh), sp, radius, rim_tabs[c])
    if stop_after == 2:
        return True
    # slope: angle between the local surface normal (from the fitted base) and the
    # normal of the reference body (the stretched sphere, S^-2 P_c; radial when
    # unstretched), so that an elongated body's shape is not mistaken for steep ground
    l0 = a0 - gx * e0v - gy * n0
    l1 = a1 - gx * e1v - gy * n1
    l2 = a2 - gx * e2v - gy * n2
    if up.shape[0] > 0:  # the given "up" (e.g. against self-gravity on a shape model)
        r0 = up[c, 0]
        r1 = up[c, 1]
        r2 = up[c, 2]
    else:
        r0 = pc0 / (stretch[0] * stretch[0])
        r1 = pc1 / (stretch[1] * stretch[1])
        r2 = pc2 / (stretch[2] * stretch[2])
    cr0 = l1 * r2 - l2 * r1
    cr1 = l2 * r0 - l0 * r2
    cr2 = l0 * r1 - l1 * r0
    slope = np.degrees(np.arctan2(np.sqrt(cr0 * cr0 + cr1 * cr1 + cr2 * cr2),
                                  l0 * r0 + l1 * r1 + l2 * r2))
    out_slope[c] = slope
    out_centre[c, 0] = pc0
    out_centre[c, 1] = pc1
    out_centre[c, 2] = pc2
    out_spacing[c] = sp
    if slope_erosion and slope >= full_deg:
        out_erased[c] = True  # steeper than the angle of repose: erased, not stamped
        return True
    scale = slope_factor(slope, onset_deg, full_deg) if slope_erosion else 1.0
    # delta = plane - terrain at the rim = -(residual grid) there
    rim_offsets(local, float(nh), float(nh), sp, radius, rim_tabs[c], 0.0, 0.0, 0.0, delta)
    octaves = roughness_octaves(radius, sp)
    dh = np.empty(keep)
    if inner_parallel and keep >= PARALLEL_MIN:
        _write_parallel(radii, idx[:keep], pmag[:keep], dist[:keep], az[:keep], xl[:keep],
                        yl[:keep], hgt[:keep], radius, tabs[c], scale, depths[c], xe,
                        rim_tabs[c], delta, p0, gx, gy, qa, qb, qc, rough, seeds[c],
                        radius, octaves, gain, dh)
    else:
        _write_range(0, keep, radii, idx, pmag, dist, az, xl, yl, hgt, radius, tabs[c],
                     scale, depths[c], xe, rim_tabs[c], delta, p0, gx, gy, qa, qb, qc,
                     rough, seeds[c], radius, octaves, gain, dh)
    big = 0.0
    for q in range(keep):
        big = max(big, abs(dh[q]))
    out_scale[c] = scale
    out_maxdh[c] = big
    out_nvert[c] = keep
    return True


@njit(cache=True)
def _stamp_body_kernel(m, ring_offsets, unit, radii, stretch, lat, lon, diam, tabs, depths,
                       rim_tabs, seeds, xe, slope_erosion, onset_deg, full_deg, rough, gain,
                       out_scale, out_slope, out_centre, out_maxdh, out_nvert, out_spacing,
                       out_erased, up, naive=False, stop_after=0):
    """Stamp craters on the body in the given order (oldest first), updating ``radii``.

    Per crater: centre on the current surface; gather the region's vertices through the
    ring structure; true distance (arc at the local radius) and azimuth (east/north at
    the centre) of each; heights radial, relative to the centre's radius; a local grid
    at the local vertex spacing (vertices binned, holes filled) for the plane fit and
    the rim offsets; the crater evaluated at every vertex with its true distance and
    azimuth (its profile table ``tabs[c]``, scaled by the slope erosion, recorded in
    ``out_scale``; ``depths[c]`` sets the roughness amplitude); radii rescaled by the
    height change. The slope for slope erosion is measured against ``up[c]`` when ``up``
    has rows (one per crater), otherwise against the reference body's normal.

    Vertex directions are computed from the ring structure (no whole-grid unit-vector
    array). Benchmark switches: ``naive`` gathers by scanning every vertex of ``unit``
    (the O(N)-per-crater reference; otherwise ``unit`` is unused and may be empty);
    ``stop_after`` = 1 stops after the gather and local coordinates, 2 after the local
    grid and base fit (to time the stages).
    """
    for c in range(lat.shape[0]):
        _stamp_one(c, m, ring_offsets, unit, radii, stretch, lat, lon, diam, tabs, depths,
                   rim_tabs, seeds, xe, slope_erosion, onset_deg, full_deg, rough, gain,
                   out_scale, out_slope, out_centre, out_maxdh, out_nvert, out_spacing,
                   out_erased, up, naive, stop_after, True, np.inf)
