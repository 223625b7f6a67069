"""Numba kernels for stamping craters on the lat/long body via local DEM mapping."""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from craters.kernels import (
    DC8,
    DR8,
    TILT_MAX_COS,
    TILT_MIN_DEG,
    crater_rough,
    fbm2,
    idw8,
    outer_weight,
    rim_offsets,
    roughness_amp,
    roughness_octaves,
    slope_factor,
    table,
    table_value,
    tilted_frame,
    warp_x,
)

from ._grid_kernels import _interpolate_one, _ring_size
from ._local_kernels import (  # noqa: F401 - re-exported for the mesh kernels and tests
    _cholesky_solve6,
    _fit_plane_points,
    _fit_quadric_points,
    _local_coordinates,
    _quadric,
    _stretched,
)
from ._tilt_kernels import _tilted_change


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


#: the first point of a serial write, typed int64 like the parallel blocks' bounds: a
#: literal 0 made numba compile the writer a second time (for the type Literal[int](0))
_FIRST = np.int64(0)

# vertices above which a crater is written in parallel: a parallel region costs tens of
# microseconds, far more when the other core is busy, so small craters stay serial
PARALLEL_MIN = 20_000


@njit(cache=True, inline="always")
def _reach(radius, rim_tab, xe):
    """Radius (metres) within which the crater changes anything: the ejecta edge at its
    widest rim."""
    rho_max = 0.0
    for k in range(rim_tab.shape[0]):
        rho_max = max(rho_max, rim_tab[k])
    return xe * radius * (1.0 + rho_max)


@njit(cache=True, inline="always")
def _height_change(q, dist, az, xl, yl, hgt, radius, tab, scale, depth, xe, rim_tab, delta,
                   p0, gx, gy, qa, qb, qc, rough, seed, wavelength, octaves, gain, far):
    """(inside the ejecta edge?, height change in metres) of gathered point ``q``: inside
    the (irregular) rim the base quadric plus the profile, outside the terrain plus the
    profile and the rim offset fading to the edge, with the roughness overlay. Beyond
    ``far`` (the ejecta edge of the widest rim, :func:`_far`) nothing changes: no rim
    lookup there (nor an azimuth: the body's local coordinates leave it 0)."""
    if dist[q] > far:
        return False, 0.0
    x = dist[q] / (radius * (1.0 + table(rim_tab, az[q])))
    if not x < xe:
        return False, 0.0
    if x <= 1.0:
        xw = warp_x(x, xl[q], yl[q], radius, rough[3], seed)
        new = _quadric(p0, gx, gy, qa, qb, qc, xl[q], yl[q]) + scale * table_value(tab, xw, xe)
    else:
        new = (hgt[q] + scale * table_value(tab, x, xe)
               + table(delta, az[q]) * outer_weight(x, xe))
    if rough[0] > 0.0 or rough[1] > 0.0 or rough[2] > 0.0:
        amp = roughness_amp(x, xe, rough[0], rough[1], rough[2]) * depth * scale
        new += amp * fbm2(seed, xl[q], yl[q], wavelength, octaves, gain)
    return True, new - hgt[q]


@njit(cache=True, inline="always")
def _far(radius, rim_tab, xe):
    """The ejecta edge of the widest rim with a margin over rounding: no point beyond it
    changes (:func:`_height_change`)."""
    return _reach(radius, rim_tab, xe) * (1.0 + 1e-12)


@njit(cache=True, inline="always")
def _point_arrays(cnt):
    """Work arrays of a crater's ``cnt`` candidate points: vertex, distance from the
    centre (|position| on the body), distance in the crater's plane, azimuth, x, y and
    height in its frame."""
    return (np.empty(cnt, np.int64), np.empty(cnt), np.empty(cnt), np.empty(cnt),
            np.empty(cnt), np.empty(cnt), np.empty(cnt))


@njit(cache=True)
def _residual_grid(xl, yl, hgt, keep, sp, limit, p0, gx, gy, qa, qb, qc):
    """The local height grid of a crater's region: the first ``keep`` points' heights
    relative to the base quadric, averaged in cells of ``sp`` metres over +-``limit``
    (cell (nh, nh) at the centre). Returns (grid, known cells, nh)."""
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
    return acc, known, nh


@njit(cache=True, inline="always")
def _slope_deg(a0, a1, a2, e0, e1, e2, n0, n1, n2, gx, gy, r0, r1, r2):
    """Angle (degrees) between the normal of the base plane (slopes gx, gy along east e and
    north n of the frame with up a) and the reference direction r."""
    l0 = a0 - gx * e0 - gy * n0
    l1 = a1 - gx * e1 - gy * n1
    l2 = a2 - gx * e2 - gy * n2
    cr0 = l1 * r2 - l2 * r1
    cr1 = l2 * r0 - l0 * r2
    cr2 = l0 * r1 - l1 * r0
    return np.degrees(np.arctan2(np.sqrt(cr0 * cr0 + cr1 * cr1 + cr2 * cr2),
                                 l0 * r0 + l1 * r1 + l2 * r2))


@njit(cache=True, inline="always")
def _record(c, scale, dh, keep, out_scale, out_maxdh, out_nvert):
    """Crater c's report: its slope-erosion factor, largest height change and the count
    of points it wrote."""
    big = 0.0
    for q in range(keep):
        big = max(big, abs(dh[q]))
    out_scale[c] = scale
    out_maxdh[c] = big
    out_nvert[c] = keep


@njit(cache=True)
def _write_range(lo, hi, radii, idx, pmag, dist, az, xl, yl, hgt, radius, tab, scale, depth, xe,
                 rim_tab, delta, p0, gx, gy, qa, qb, qc, rough, seed, wavelength, octaves, gain,
                 fr, dh_out):
    """New radii for gathered vertices lo..hi-1 (each vertex written once): the radial
    vector rescaled by the height change (in the tilted base's frame ``fr`` when its
    ``fr[9]`` > 0, :func:`_tilted_change`)."""
    far = _far(radius, rim_tab, xe)
    tilted = fr[9] > 0.0
    for q in range(lo, hi):
        if tilted:
            if dist[q] > far:
                inside, dh = False, 0.0
            else:
                inside, dh = _tilted_change(q, xl, yl, hgt, radius, tab, scale, depth, xe,
                                            rim_tab, delta, p0, qa, qb, qc, rough, seed,
                                            wavelength, octaves, gain, fr)
        else:
            inside, dh = _height_change(q, dist, az, xl, yl, hgt, radius, tab, scale, depth,
                                        xe, rim_tab, delta, p0, gx, gy, qa, qb, qc, rough,
                                        seed, wavelength, octaves, gain, far)
        if inside:
            i = idx[q]
            radii[i] = radii[i] * (pmag[q] + dh) / pmag[q]
        dh_out[q] = dh


@njit(cache=True, parallel=True)
def _write_parallel(radii, idx, pmag, dist, az, xl, yl, hgt, radius, tab, scale, depth, xe,
                    rim_tab, delta, p0, gx, gy, qa, qb, qc, rough, seed, wavelength, octaves,
                    gain, fr, dh_out):
    """:func:`_write_range` over blocks of vertices in parallel (blocks are disjoint)."""
    n = idx.shape[0]
    block = 4096
    for b in prange((n + block - 1) // block):
        _write_range(b * block, min(n, (b + 1) * block), radii, idx, pmag, dist, az, xl, yl,
                     hgt, radius, tab, scale, depth, xe, rim_tab, delta, p0, gx, gy, qa, qb,
                     qc, rough, seed, wavelength, octaves, gain, fr, dh_out)


@njit(cache=True)
def _stamp_one(c, m, ring_offsets, unit, radii, stretch, lat, lon, diam, tabs, depths, warps,
               rim_tabs, seeds, xe, slope_erosion, onset_deg, full_deg, rough, gain, out_scale,
               out_slope, out_centre, out_maxdh, out_nvert, out_spacing, out_erased, up, naive,
               stop_after, inner_parallel, ang_bound):
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
    reach = _reach(radius, rim_tabs[c], xe)
    nominal = rloc * np.pi / (2 * m)
    ang = min(np.pi, (reach + 2.0 * nominal) / rloc * smax / smin)
    if ang > ang_bound:
        return False  # the surface moved more than the wave schedule allowed for
    if naive:
        cand = _scan_all(unit, uc0, uc1, uc2, np.cos(ang))
        cnt = cand.shape[0]
    else:
        cnt = _gather_kernel(m, ring_offsets, colat, lo, ang, np.empty(0, np.int64),
                             np.bool_(True))
        cand = np.empty(cnt, np.int64)
        _gather_kernel(m, ring_offsets, colat, lo, ang, cand, np.bool_(False))
    # local coordinates of the candidates
    idx, pmag, dist, az, xl, yl, hgt = _point_arrays(cnt)
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
    acc, known, nh = _residual_grid(xl, yl, hgt, keep, sp, limit, p0, gx, gy, qa, qb, qc)
    local = _fill_rim_cells(acc, known, float(nh), float(nh), sp, radius, rim_tabs[c])
    if stop_after == 2:
        return True
    # slope: angle between the local surface normal (from the fitted base) and the
    # normal of the reference body (the stretched sphere, S^-2 P_c; radial when
    # unstretched), so that an elongated body's shape is not mistaken for steep ground
    if up.shape[0] > 0:  # the given "up" (e.g. against self-gravity on a shape model)
        r0 = up[c, 0]
        r1 = up[c, 1]
        r2 = up[c, 2]
    else:
        r0 = pc0 / (stretch[0] * stretch[0])
        r1 = pc1 / (stretch[1] * stretch[1])
        r2 = pc2 / (stretch[2] * stretch[2])
    slope = _slope_deg(a0, a1, a2, e0v, e1v, e2v, n0, n1, n2, gx, gy, r0, r1, r2)
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
    rough = crater_rough(rough, warps[c])
    # on steep ground the crater is made in its base's frame (issue 36)
    fr = np.zeros(10)
    tilt = tilted_frame(gx, gy, fr)
    if tilt < TILT_MIN_DEG or fr[9] < TILT_MAX_COS:
        fr[9] = 0.0
    dh = np.empty(keep)
    if inner_parallel and keep >= PARALLEL_MIN:
        _write_parallel(radii, idx[:keep], pmag[:keep], dist[:keep], az[:keep], xl[:keep],
                        yl[:keep], hgt[:keep], radius, tabs[c], scale, depths[c], xe,
                        rim_tabs[c], delta, p0, gx, gy, qa, qb, qc, rough, seeds[c],
                        radius, octaves, gain, fr, dh)
    else:
        _write_range(_FIRST, keep, radii, idx, pmag, dist, az, xl, yl, hgt, radius, tabs[c],
                     scale, depths[c], xe, rim_tabs[c], delta, p0, gx, gy, qa, qb, qc,
                     rough, seeds[c], radius, octaves, gain, fr, dh)
    _record(c, scale, dh, keep, out_scale, out_maxdh, out_nvert)
    return True


@njit(cache=True, nogil=True)
def _stamp_body_kernel(m, ring_offsets, unit, radii, stretch, lat, lon, diam, tabs, depths,
                       warps, rim_tabs, seeds, xe, slope_erosion, onset_deg, full_deg, rough, gain,
                       out_scale, out_slope, out_centre, out_maxdh, out_nvert, out_spacing,
                       out_erased, up, naive=False, stop_after=0):
    """Stamp craters on the body in the given order (oldest first), updating ``radii``.

    Per crater: centre on the current surface; gather the region's vertices through the
    ring structure; true distance (arc at the local radius) and azimuth (east/north at
    the centre) of each; heights radial, relative to the centre's radius; a local grid
    at the local vertex spacing (vertices binned, holes filled) for the plane fit and
    the rim offsets; the crater evaluated at every vertex with its true distance and
    azimuth (its profile table ``tabs[c]``, scaled by the slope erosion, recorded in
    ``out_scale``; ``depths[c]`` sets the roughness amplitude, ``warps[c]`` the wall warp of
    :func:`craters.kernels.warp_x`); radii rescaled by the
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
                   warps, rim_tabs, seeds, xe, slope_erosion, onset_deg, full_deg, rough, gain,
                   out_scale, out_slope, out_centre, out_maxdh, out_nvert, out_spacing,
                   out_erased, up, np.bool_(naive), np.int64(stop_after), np.bool_(True), np.inf)
