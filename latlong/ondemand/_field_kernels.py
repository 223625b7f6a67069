"""Numba kernels of the local crater field (:mod:`latlong.ondemand.field`).

Every value at a point is computed by one thread from that point's own data in a fixed
order, so no result depends on which other points are asked with it or on the thread
count. References in numpy: ``tests/latlong/test_ondemand.py``.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from craters.kernels import (
    TILT_MAX_COS,
    TILT_MIN_DEG,
    azimuth,
    fbm2,
    read_only_inputs,
    roughness_amp,
    slope_factor,
    table_row,
    table_row_value,
    tilted_coords,
    tilted_ejecta,
    tilted_frame,
    tilted_root,
    warp_x,
)

# crater record columns (float64 array "fc", one row per crater)
C0, C1, C2 = 0, 1, 2          # centre direction (unit)
E0, E1, E2 = 3, 4, 5          # east at the centre
N0, N1, N2 = 6, 7, 8          # north at the centre
RHO = 9                       # reference radius (the base's, m)
RAD = 10                      # crater radius (m)
COS_FAR = 11                  # cos of the widest ejecta edge's angle
P0, GX, GY, QA, QB, QC = 12, 13, 14, 15, 16, 17   # base quadric (radial heights over RHO)
SCALE = 18                    # slope-erosion factor of the relief
DEPTH = 19                    # rim crest to floor of the table (m)
ACTIVE = 20                   # 1 when stamped (0: erased by slope erosion, or no params yet)
FAR = 21                      # the widest ejecta edge's angle (radians)
CHORD2 = 22                   # squared chord of that angle, (2 sin(FAR / 2))^2
WARP = 23                     # wall warp (craters.kernels.warp_x): 0 simple .. 1 complex
TILT = 24                     # the tilted base's frame E', N', N (9) and N_z (0: radial frame)
TILT_CZ = TILT + 9
N_COLS = TILT + 10


@njit(cache=True, inline="always")
def _local(fc, k, p0, p1, p2):
    """(cos angle, distance in metres, x, y in the crater's frame, east and north
    components) of direction p from crater k's centre (azimuthal equidistant at the
    crater's reference radius); ``arctan2(north, east)`` is its azimuth (0 at the
    centre, where both are +0)."""
    c = fc[k, C0] * p0 + fc[k, C1] * p1 + fc[k, C2] * p2
    xe = fc[k, E0] * p0 + fc[k, E1] * p1 + fc[k, E2] * p2
    xn = fc[k, N0] * p0 + fc[k, N1] * p1 + fc[k, N2] * p2
    s = np.sqrt(xe * xe + xn * xn)
    if s < 0.01 and c > 0.0:  # asin's series: the angle to ~1e-18 (relative), no arctan
        s2 = s * s
        dist = s * (1.0 + s2 * (1.0 / 6.0 + s2 * (3.0 / 40.0 + s2 * (5.0 / 112.0)))) \
            * fc[k, RHO]
    else:
        dist = np.arctan2(s, c) * fc[k, RHO]
    if s > 0.0:
        return c, dist, dist * xe / s, dist * xn / s, xe, xn
    return c, dist, 0.0, 0.0, 0.0, 0.0


@njit(cache=True, inline="always")
def _far(rec, k, col, p0, p1, p2):
    """Whether direction p is farther from record k's centre than the angle whose squared
    chord is ``rec[k, col]``: by the chord, exact to the last bits at any angle (a cosine
    test loses everything below ~1e-8 rad: centimetres on the Moon)."""
    d0 = p0 - rec[k, C0]
    d1 = p1 - rec[k, C1]
    d2 = p2 - rec[k, C2]
    return d0 * d0 + d1 * d1 + d2 * d2 > rec[k, col]


@njit(cache=True, inline="always")
def _quadric(fc, k, x, y):
    return (fc[k, P0] + fc[k, GX] * x + fc[k, GY] * y + fc[k, QA] * x * x
            + fc[k, QB] * x * y + fc[k, QC] * y * y)


@njit(cache=True, inline="always")
def _step(fc, k, tabs, rims, seeds, rough, gain, octaves, xe, xb, p0, p1, p2):
    """Crater k at direction p as an affine map of the height before it, h -> a h + b:
    (touched?, a, b). Inside the rim a = 0 (the crater replaces what was there: its base
    quadric plus its profile); outside, the profile adds to the old terrain, which is
    blended into the base quadric towards the rim (weight a = 1 - ((xb - x)/(xb - 1))^2
    from the rim to ``xb`` radii, 1 beyond), so the rim is continuous whatever the older
    terrain is."""
    if _far(fc, k, CHORD2, p0, p1, p2):
        return False, 1.0, 0.0  # beyond the widest ejecta edge: nothing else to compute
    cosang, dist, x, y, ue, un = _local(fc, k, p0, p1, p2)
    if fc[k, TILT_CZ] > 0.0:
        return _tilted_step(fc, k, tabs, rims, seeds, rough, gain, octaves, xe, xb, x, y)
    radius = fc[k, RAD]
    xr = dist / (radius * (1.0 + table_row(rims, k, azimuth(un, ue))))
    if not xr < xe:
        return False, 1.0, 0.0
    scale = fc[k, SCALE]
    prof = scale * table_row_value(tabs, k, warp_x(xr, x, y, radius, fc[k, WARP], seeds[k]), xe)
    if octaves > 0 and (rough[0] > 0.0 or rough[1] > 0.0 or rough[2] > 0.0):
        amp = roughness_amp(xr, xe, rough[0], rough[1], rough[2]) * fc[k, DEPTH] * scale
        # below a millionth of the radius (a crater diffused flat) the overlay is left out:
        # a property of the crater, the same wherever it is evaluated
        if amp > 1e-6 * radius:
            prof += amp * fbm2(seeds[k], x, y, radius, octaves, gain)
    q = fc[k, RHO] + _quadric(fc, k, x, y)
    if xr <= 1.0:
        return True, 0.0, q + prof
    if xr < xb:
        t = (xb - xr) / (xb - 1.0)
        w = 1.0 - t * t
        return True, w, (1.0 - w) * q + prof
    return True, 1.0, prof


@njit(cache=True)
def _tilted_step(fc, k, tabs, rims, seeds, rough, gain, octaves, xe, xb, x, y):
    """:func:`_step` of a crater made in its tilted base's frame (as the sequential stamp,
    the body's :func:`latlong._tilt_kernels._tilted_change`): the point's in-plane coordinates and
    height along the base normal are those of its foot on the base plane, so the map
    does not depend on the height before it; inside the rim the radius where the radial
    line meets the crater's surface over the base plane (plus the base's curvature,
    radially), outside the profile along the normal (over N_z)."""
    fr = fc[k, TILT:TILT + 10]
    r2 = fc[k, GX] * x + fc[k, GY] * y  # the foot on the base plane (w0 = 0 but rounding)
    radius = fc[k, RAD]
    u1, u2, w0, _, xr = tilted_coords(x, y, r2, fr, radius, rims[k])
    if not xr < xe:
        return False, 1.0, 0.0
    scale = fc[k, SCALE]
    amp_max = max(rough[0], max(rough[1], rough[2])) * fc[k, DEPTH] * scale
    has_rough = octaves > 0 and amp_max > 1e-6 * radius
    if xr <= 1.0:
        # the crater over its base plane in the plane's frame; the base's curvature (the
        # quadric's quadratic part) radially, as outside: the rim meets the blend whatever
        # the curvature (a crater in a larger crater's bowl: 100 m over its radius)
        t_root = tilted_root(u1, u2, w0, radius, tabs[k], scale, fc[k, DEPTH], xe, rims[k],
                             rough, fc[k, WARP], has_rough, seeds[k], radius, octaves, gain, fr)
        return True, 0.0, (fc[k, RHO] + _quadric(fc, k, x, y)) + t_root
    prof = tilted_ejecta(xr, xe, u1, u2, tabs[k], scale, fc[k, DEPTH], rough, has_rough,
                         seeds[k], radius, octaves, gain, fr[9])
    if xr < xb:
        t = (xb - xr) / (xb - 1.0)
        w = 1.0 - t * t
        return True, w, (1.0 - w) * (fc[k, RHO] + _quadric(fc, k, x, y)) + prof
    return True, 1.0, prof


@njit(cache=True, inline="always")
def _compose(order, lo, hi, fc, tabs, rims, seeds, rough, gain, octaves, xe, xb, p0, p1, p2,
             base, older_than, age_key, d_above, diam):
    """Height at p from craters ``order[lo:hi]`` (youngest first) over ``base``: the
    composition of their affine maps, stopping at the first rim that holds p. With
    ``older_than`` >= 0 only craters older than that age key and larger than ``d_above``
    count (a crater's base: the terrain of the older, larger craters)."""
    a = 1.0
    b = 0.0
    for t in range(lo, hi):
        k = order[t]
        if fc[k, ACTIVE] == 0.0:
            continue
        if older_than >= 0 and (age_key[k] <= older_than or not diam[k] > d_above):
            continue
        hit, ak, bk = _step(fc, k, tabs, rims, seeds, rough, gain, octaves, xe, xb, p0, p1, p2)
        if not hit:
            continue
        b += a * bk
        a *= ak
        if a == 0.0:
            return b
    return b + a * base


@njit(cache=True)
def _generations_kernel(todo, dep_start, dep_list, gen):
    """Generation of each crater: 0 without dependencies, else one more than its
    dependencies' largest (``todo`` lists dependencies before their owners)."""
    for t in range(todo.shape[0]):
        k = todo[t]
        g = 0
        for q in range(dep_start[k], dep_start[k + 1]):
            g = max(g, gen[dep_list[q]] + 1)
        gen[k] = g


# fc is writable in both kernels that compose craters (the parameters kernel writes it):
# _tilted_step, which both call, then compiles once, not once per array type
@read_only_inputs("fc")
@njit(cache=True, parallel=True)
def _params_kernel(todo, gen_start, dep_start, dep_list, stencil, st_base, fit, fc, tabs, rims,
                   seeds, rough, gain, octaves, xe, xb, age_key, diam, up, onset, full,
                   slope_erosion):
    """Base quadric and slope-erosion factor of each crater (:func:`_crater_params`),
    generation by generation (``todo[gen_start[g]:gen_start[g + 1]]``), the craters of a
    generation in parallel: each reads only craters of earlier generations."""
    for g in range(gen_start.shape[0] - 1):
        for t in prange(gen_start[g], gen_start[g + 1]):
            _crater_params(todo[t], dep_start, dep_list, stencil, st_base, fit, fc, tabs, rims,
                           seeds, rough, gain, octaves, xe, xb, age_key, diam, up, onset, full,
                           slope_erosion)


@njit(cache=True, inline="always")
def _crater_params(k, dep_start, dep_list, stencil, st_base, fit, fc, tabs, rims, seeds,
                   rough, gain, octaves, xe, xb, age_key, diam, up, onset, full, slope_erosion):
    """Base quadric and slope-erosion factor of crater k: the terrain of its older, larger
    craters (``dep_list[dep_start[k]:dep_start[k+1]]``, youngest first, roughness overlay
    included: at a smaller crater's scale a larger crater's overlay is a smooth offset,
    metres on the Moon, not noise a fit averages out) at its stencil points, fitted by
    the fixed least-squares operator ``fit`` (6, n_stencil) in the crater's normalised
    coordinates."""
    n_st = stencil.shape[1]
    h = np.empty(n_st)
    for s in range(n_st):
        h[s] = _compose(dep_list, dep_start[k], dep_start[k + 1], fc, tabs, rims, seeds,
                        rough, gain, octaves, xe, xb, stencil[k, s, 0], stencil[k, s, 1],
                        stencil[k, s, 2], st_base[k, s], age_key[k], age_key, diam[k],
                        diam) - fc[k, RHO]
    coef = np.zeros(6)
    for r in range(6):
        acc = 0.0
        for s in range(n_st):
            acc += fit[r, s] * h[s]
        coef[r] = acc
    radius = fc[k, RAD]
    fc[k, P0] = coef[0]
    fc[k, GX] = coef[1] / radius
    fc[k, GY] = coef[2] / radius
    fc[k, QA] = coef[3] / (radius * radius)
    fc[k, QB] = coef[4] / (radius * radius)
    fc[k, QC] = coef[5] / (radius * radius)
    # slope: the base plane's normal against "up"
    gx = fc[k, GX]
    gy = fc[k, GY]
    l0 = fc[k, C0] - gx * fc[k, E0] - gy * fc[k, N0]
    l1 = fc[k, C1] - gx * fc[k, E1] - gy * fc[k, N1]
    l2 = fc[k, C2] - gx * fc[k, E2] - gy * fc[k, N2]
    r0 = up[k, 0]
    r1 = up[k, 1]
    r2 = up[k, 2]
    cr0 = l1 * r2 - l2 * r1
    cr1 = l2 * r0 - l0 * r2
    cr2 = l0 * r1 - l1 * r0
    slope = np.degrees(np.arctan2(np.sqrt(cr0 * cr0 + cr1 * cr1 + cr2 * cr2),
                                  l0 * r0 + l1 * r1 + l2 * r2))
    # on steep ground the crater is made in its base's frame (issue 36), as sequentially
    if tilted_frame(gx, gy, fc[k, TILT:TILT + 10]) < TILT_MIN_DEG \
            or fc[k, TILT_CZ] < TILT_MAX_COS:
        fc[k, TILT_CZ] = 0.0
    scale = slope_factor(slope, onset, full) if slope_erosion else 1.0
    if slope_erosion and slope >= full:
        scale = 0.0  # steeper than the angle of repose: erased, not stamped
    fc[k, SCALE] = scale
    fc[k, ACTIVE] = 1.0 if scale > 0.0 else 0.0


@read_only_inputs("out", "fc")
@njit(cache=True, parallel=True)
def _points_kernel(points, block_of, blk_start, blk_list, base, fc, tabs, rims, seeds, rough,
                   gain, octaves, xe, xb, age_key, diam, out):
    """Radius at each point: the composition over its block's craters (youngest first)."""
    for i in prange(points.shape[0]):
        blk = block_of[i]
        out[i] = _compose(blk_list, blk_start[blk], blk_start[blk + 1], fc, tabs, rims, seeds,
                          rough, gain, octaves, xe, xb, points[i, 0], points[i, 1],
                          points[i, 2], base[i], -1, age_key, 0.0, diam)


@njit(cache=True, inline="always")
def _own_angle_chord(fc, o):
    """Owner ``o``'s angular radius, widened by 1e-9, and its chord."""
    own = fc[o, RAD] / fc[o, RHO] * (1.0 + 1e-9)
    return own, 2.0 * np.sin(0.5 * own)


@njit(cache=True, inline="always")
def _dep_scan(s, owners, owner_cell, c_start, c_list, fc, diam, out_owner, out_dep, at,
              write):
    """The pairs of owner ``owners[s]`` (:func:`_dep_kernel`), written from ``at`` when
    ``write``; returns how many."""
    n = 0
    o = owners[s]
    c = owner_cell[s]
    own, chord_own = _own_angle_chord(fc, o)
    for q in range(c_start[c], c_start[c + 1]):
        k = c_list[q]
        if not diam[k] > diam[o]:
            continue
        # within the ejecta edge's angle plus the owner's: the chords add up to at
        # least the chord of the sum (a superset: exact at small angles, no cosine)
        d0 = fc[k, C0] - fc[o, C0]
        d1 = fc[k, C1] - fc[o, C1]
        d2 = fc[k, C2] - fc[o, C2]
        lim = np.sqrt(fc[k, CHORD2]) + chord_own
        if fc[k, FAR] + own >= np.pi or d0 * d0 + d1 * d1 + d2 * d2 <= lim * lim:
            if write:
                out_owner[at + n] = o
                out_dep[at + n] = k
            n += 1
    return n


@njit(cache=True, inline="always")
def _may_reach_cell(fc, k, r, reach, own_max):
    """Whether candidate ``k`` may pass :func:`_dep_scan`'s test for an owner of a cell
    whose owners lie within ``reach`` (chord plus own chord) of its owner ``r``."""
    if fc[k, FAR] + own_max >= np.pi:
        return True
    d0 = fc[k, C0] - fc[r, C0]
    d1 = fc[k, C1] - fc[r, C1]
    d2 = fc[k, C2] - fc[r, C2]
    lim = (np.sqrt(fc[k, CHORD2]) + reach) * (1.0 + 1e-12)
    return d0 * d0 + d1 * d1 + d2 * d2 <= lim * lim


@njit(cache=True)
def _cell_candidates(owners, owner_cell, lo, hi, cand_sorted, fc):
    """The candidates each owner cell's owners must test, in the order ``lo``/``hi``
    give (t = 0..8, then q): (starts (n_cells + 1), list). A candidate is left out when
    no owner of the cell can pass :func:`_dep_scan`'s test, by the triangle inequality
    around the cell's first owner ``r``: a pair passes only if |k - o| <= chord_k +
    chord_o, and |k - r| <= |k - o| + |o - r|, so the candidates with |k - r| >
    chord_k + max_o (chord_o + |o - r|) are none of them (kept with a margin of 1e-12
    for rounding: only a superset, the same pairs in the same order). In a coarse bin
    ~10 000 owners in a few cells share a few hundred candidates, 1 % of them near.
    Every cell of ``lo`` holds an owner."""
    n_cell = lo.shape[0]
    ref = np.full(n_cell, -1, dtype=np.int64)
    reach = np.zeros(n_cell)
    own_max = np.zeros(n_cell)
    for s in range(owners.shape[0]):
        o = owners[s]
        c = owner_cell[s]
        if ref[c] < 0:
            ref[c] = o
        r = ref[c]
        d0 = fc[o, C0] - fc[r, C0]
        d1 = fc[o, C1] - fc[r, C1]
        d2 = fc[o, C2] - fc[r, C2]
        own, chord_own = _own_angle_chord(fc, o)
        reach[c] = max(reach[c], np.sqrt(d0 * d0 + d1 * d1 + d2 * d2) + chord_own)
        own_max[c] = max(own_max[c], own)
    starts = np.zeros(n_cell + 1, dtype=np.int64)
    for c in range(n_cell):  # counted first, then written at the cells' offsets
        n = 0
        for t in range(9):
            for q in range(lo[c, t], hi[c, t]):
                n += _may_reach_cell(fc, cand_sorted[q], ref[c], reach[c], own_max[c])
        starts[c + 1] = starts[c] + n
    c_list = np.empty(starts[n_cell], dtype=np.int64)
    for c in range(n_cell):
        at = starts[c]
        for t in range(9):
            for q in range(lo[c, t], hi[c, t]):
                k = cand_sorted[q]
                if _may_reach_cell(fc, k, ref[c], reach[c], own_max[c]):
                    c_list[at] = k
                    at += 1
    return starts, c_list


@njit(cache=True, parallel=True)
def _dep_kernel(owners, owner_cell, lo, hi, cand_sorted, fc, diam):
    """Pairs (owner, candidate) where a candidate crater of the bin is larger than the
    owner and its ejecta reach the owner's rim disc (centres within the candidate's widest
    ejecta edge plus the owner's radius), owner by owner in the order given: (owners,
    deps). The candidates of the cells around owner ``s``'s cell ``c = owner_cell[s]``
    are ``cand_sorted[lo[c, t]:hi[c, t]]``, t = 0..8 (each cell once), narrowed per cell
    by :func:`_cell_candidates`. Owners in parallel, counted first, then written at their
    offsets."""
    c_start, c_list = _cell_candidates(owners, owner_cell, lo, hi, cand_sorted, fc)
    n_own = owners.shape[0]
    counts = np.zeros(n_own + 1, dtype=np.int64)
    none = np.empty(0, dtype=np.int64)
    for s in prange(n_own):
        counts[s + 1] = _dep_scan(s, owners, owner_cell, c_start, c_list, fc, diam, none,
                                  none, 0, False)
    offsets = np.cumsum(counts)
    out_owner = np.empty(offsets[n_own], dtype=np.int64)
    out_dep = np.empty(offsets[n_own], dtype=np.int64)
    for s in prange(n_own):
        if counts[s + 1] > 0:  # most owners have none in a bin of larger craters
            _dep_scan(s, owners, owner_cell, c_start, c_list, fc, diam, out_owner,
                      out_dep, offsets[s], True)
    return out_owner, out_dep


@njit(cache=True, parallel=True)
def _stencil_kernel(fc, st_xy, out):
    """Directions (n, s, 3) of each crater's stencil points: at angle r R / rho from its
    centre towards azimuth atan2(y, x) (east = x), for the normalised (x, y) of
    ``st_xy``."""
    for k in prange(fc.shape[0]):
        scale = fc[k, RAD] / fc[k, RHO]
        for s in range(st_xy.shape[0]):
            tx = st_xy[s, 0] * scale
            ty = st_xy[s, 1] * scale
            ang = np.sqrt(tx * tx + ty * ty)
            if ang > 0.0:
                ce = tx / ang
                cn = ty / ang
            else:
                ce = 0.0
                cn = 0.0
            sa = np.sin(ang)
            ca = np.cos(ang)
            for d in range(3):
                out[k, s, d] = ca * fc[k, C0 + d] + sa * (ce * fc[k, E0 + d] + cn * fc[k, N0 + d])


@njit(cache=True)
def _fit_operator(st_xy):
    """The least-squares operator (6, n) of the quadric 1, x, y, x^2, xy, y^2 at the
    stencil's normalised coordinates (normal equations, Cholesky, fixed order)."""
    n = st_xy.shape[0]
    a = np.empty((n, 6))
    for s in range(n):
        x = st_xy[s, 0]
        y = st_xy[s, 1]
        a[s, 0] = 1.0
        a[s, 1] = x
        a[s, 2] = y
        a[s, 3] = x * x
        a[s, 4] = x * y
        a[s, 5] = y * y
    ata = np.zeros((6, 6))
    for r in range(6):
        for c in range(6):
            acc = 0.0
            for s in range(n):
                acc += a[s, r] * a[s, c]
            ata[r, c] = acc
    # Cholesky
    lo = np.zeros((6, 6))
    for r in range(6):
        for c in range(r + 1):
            acc = ata[r, c]
            for t in range(c):
                acc -= lo[r, t] * lo[c, t]
            if r == c:
                lo[r, c] = np.sqrt(acc)
            else:
                lo[r, c] = acc / lo[c, c]
    out = np.empty((6, n))
    y = np.empty(6)
    for s in range(n):
        # solve (L L^T) x = a[s]
        for r in range(6):
            acc = a[s, r]
            for t in range(r):
                acc -= lo[r, t] * y[t]
            y[r] = acc / lo[r, r]
        for r in range(5, -1, -1):
            acc = y[r]
            for t in range(r + 1, 6):
                acc -= lo[t, r] * out[t, s]
            out[r, s] = acc / lo[r, r]
    return out
