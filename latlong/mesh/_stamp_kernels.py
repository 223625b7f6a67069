"""Numba kernels for stamping craters on a triangle mesh via local height grids.

The lat/long body's method (Martin 2014 V.A; :mod:`latlong._crater_kernels`) on any
closed mesh: the crater's region is gathered over the mesh's own edges (geodesic reach,
so the other side of a thin part or of a neck is never touched), mapped to a local frame
whose up axis is the surface normal averaged over the obliterated region, and the
crater is evaluated at every vertex with its true distance in that frame. Vertices move
along the frame's up axis, so their positions in the frame's plane stay where they are
and no triangle of the region turns over.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from craters.kernels import crater_rough, rim_offsets, roughness_octaves, slope_factor

from .._crater_kernels import (
    _FIRST,
    PARALLEL_MIN,
    _far,
    _fill_holes,
    _fit_quadric_points,
    _height_change,
    _point_arrays,
    _reach,
    _record,
    _residual_grid,
    _slope_deg,
)
from ..geometry._normal_kernels import _triangle_cross
from ._kernels import _geodesic_gather

#: Graph distance over straight-line distance allowed when gathering a region: mesh
#: paths are up to ~15 % longer than geodesics, and the walls of older craters make the
#: surface up to ~30 % longer than its footprint in the crater's plane.
GATHER_FACTOR = 1.6


@njit(cache=True)
def _write_range(lo, hi, pos, heights, idx, dist, az, xl, yl, hgt, up, radius, tab, scale,
                 depth, xe, rim_tab, delta, quad, rough, seed, wavelength, octaves, gain,
                 dh_out):
    """Move gathered vertices lo..hi-1 along ``up`` by their height change (each vertex
    written once; the change: :func:`~latlong._crater_kernels._height_change`)."""
    far = _far(radius, rim_tab, xe)
    for q in range(lo, hi):
        inside, dh = _height_change(q, dist, az, xl, yl, hgt, radius, tab, scale, depth, xe,
                                    rim_tab, delta, quad[0], quad[1], quad[2], quad[3],
                                    quad[4], quad[5], rough, seed, wavelength, octaves, gain,
                                    far)
        if inside:
            i = idx[q]
            pos[i, 0] += dh * up[0]
            pos[i, 1] += dh * up[1]
            pos[i, 2] += dh * up[2]
            heights[i] += dh
        dh_out[q] = dh


@njit(cache=True, parallel=True)
def _write_parallel(pos, heights, idx, dist, az, xl, yl, hgt, up, radius, tab, scale, depth,
                    xe, rim_tab, delta, quad, rough, seed, wavelength, octaves, gain, dh_out):
    """:func:`_write_range` over disjoint blocks of vertices in parallel."""
    n = idx.shape[0]
    block = 4096
    for b in prange((n + block - 1) // block):
        _write_range(b * block, min(n, (b + 1) * block), pos, heights, idx, dist, az, xl, yl,
                     hgt, up, radius, tab, scale, depth, xe, rim_tab, delta, quad, rough, seed,
                     wavelength, octaves, gain, dh_out)


@njit(cache=True, inline="always")
def _face_normal_sum(pos, faces, f, acc):
    """``acc`` = face f's cross product (twice its area along its normal)."""
    acc[0], acc[1], acc[2] = _triangle_cross(pos, faces[f, 0], faces[f, 1], faces[f, 2])


@njit(cache=True)
def _frame(n0, n1, n2):
    """(east, north) completing the up axis n: east = z x n (x x n near the poles)."""
    if abs(n2) < 0.9:
        e0, e1, e2 = -n1, n0, 0.0
    else:
        e0, e1, e2 = 0.0, -n2, n1
    en = np.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
    e0 /= en
    e1 /= en
    e2 /= en
    return e0, e1, e2, n1 * e2 - n2 * e1, n2 * e0 - n0 * e2, n0 * e1 - n1 * e0


@njit(cache=True)
def _stamp_mesh_kernel(pos, heights, faces, voff, vnbr, foff, fids, face_of, uv, vertical,
                       diam, tabs, depths, warps, rim_tabs, seeds, xe, slope_erosion, onset_deg,
                       full_deg, rough, gain, cos_tilt, mark, gdist, epoch, out_scale,
                       out_slope, out_centre, out_normal, out_maxdh, out_nvert, out_spacing,
                       out_state):
    """Stamp craters in the given order (oldest first), moving ``pos`` (and adding the
    change to ``heights``).

    Per crater: its centre on the current surface (face ``face_of[c]`` at ``uv[c]``);
    the vertices within graph distance GATHER_FACTOR x (reach + 2 spacings) of it; the
    local spacing from the vertex count inside the reach; the up axis = the area-
    weighted normal of the faces around the obliterated region; every vertex's position
    in that frame (x, y in the plane, h along up); the region refused (``out_state`` 2)
    when one of its faces inside the reach turns more than the tilt limit from up (the
    surface there is no height field over the crater's plane: a fold, a thin edge);
    then the base quadric, the local height grid, slope erosion against the crater's
    vertical ``vertical[c]`` (unit, against gravity; ``out_state`` 1 = erased on steep
    ground) and the
    crater written as on the lat/long body (:mod:`latlong._crater_kernels`).
    ``epoch`` (one-element array) counts gathers for the ``mark`` work array.
    """
    n_rim = rim_tabs.shape[1]
    delta = np.empty(n_rim)
    seed_v = np.empty(3, np.int64)
    seed_d = np.empty(3)
    acc = np.empty(3)
    up = np.empty(3)
    quad = np.empty(6)
    for c in range(diam.shape[0]):
        f = face_of[c]
        u = uv[c, 0]
        v = uv[c, 1]
        pc0 = 0.0
        pc1 = 0.0
        pc2 = 0.0
        for k in range(3):
            w = (1.0 - u - v) if k == 0 else (u if k == 1 else v)
            vk = faces[f, k]
            pc0 += w * pos[vk, 0]
            pc1 += w * pos[vk, 1]
            pc2 += w * pos[vk, 2]
        edge = 0.0
        for k in range(3):
            a = faces[f, k]
            b = faces[f, (k + 1) % 3]
            d0 = pos[a, 0] - pos[b, 0]
            d1 = pos[a, 1] - pos[b, 1]
            d2 = pos[a, 2] - pos[b, 2]
            edge += np.sqrt(d0 * d0 + d1 * d1 + d2 * d2) / 3.0
            seed_v[k] = a
            d0 = pos[a, 0] - pc0
            d1 = pos[a, 1] - pc1
            d2 = pos[a, 2] - pc2
            seed_d[k] = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        radius = 0.5 * diam[c]
        reach = _reach(radius, rim_tabs[c], xe)
        epoch[0] += 1
        cand, gd = _geodesic_gather(pos, voff, vnbr, seed_v, seed_d,
                                    GATHER_FACTOR * (reach + 2.0 * edge) + edge, mark, gdist,
                                    epoch[0])
        cnt = cand.shape[0]
        n_in = 0
        for q in range(cnt):
            if gd[q] <= reach:
                n_in += 1
        sp = np.sqrt(np.pi * reach * reach / n_in) if n_in >= 4 else max(edge, 0.5 * reach)
        r_fit = max(radius, 2.0 * sp)
        # up axis: area-weighted normal of the faces around the obliterated region
        s0 = 0.0
        s1 = 0.0
        s2 = 0.0
        for q in range(cnt):
            if gd[q] > r_fit and q >= 3:
                continue
            i = cand[q]
            for t in range(foff[i], foff[i + 1]):
                _face_normal_sum(pos, faces, fids[t], acc)
                s0 += acc[0]
                s1 += acc[1]
                s2 += acc[2]
        sn = np.sqrt(s0 * s0 + s1 * s1 + s2 * s2)
        up[0] = s0 / sn
        up[1] = s1 / sn
        up[2] = s2 / sn
        e0, e1, e2, n0, n1, n2 = _frame(up[0], up[1], up[2])
        # positions in the crater's frame
        limit = reach + 2.0 * sp
        idx, _, dist, az, xl, yl, hgt = _point_arrays(cnt)
        keep = np.int64(0)  # not a literal 0: one compile of the helpers it reaches
        n_inside = 0
        folded = False
        for q in range(cnt):
            i = cand[q]
            r0 = pos[i, 0] - pc0
            r1 = pos[i, 1] - pc1
            r2 = pos[i, 2] - pc2
            x = r0 * e0 + r1 * e1 + r2 * e2
            y = r0 * n0 + r1 * n1 + r2 * n2
            d = np.sqrt(x * x + y * y)
            if d > limit:
                continue
            if d <= reach:
                n_inside += 1
                for t in range(foff[i], foff[i + 1]):
                    _face_normal_sum(pos, faces, fids[t], acc)
                    an = np.sqrt(acc[0] * acc[0] + acc[1] * acc[1] + acc[2] * acc[2])
                    if acc[0] * up[0] + acc[1] * up[1] + acc[2] * up[2] <= cos_tilt * an:
                        folded = True
            idx[keep] = i
            dist[keep] = d
            az[keep] = np.arctan2(y, x)
            xl[keep] = x
            yl[keep] = y
            hgt[keep] = r0 * up[0] + r1 * up[1] + r2 * up[2]
            keep += 1
        out_centre[c, 0] = pc0
        out_centre[c, 1] = pc1
        out_centre[c, 2] = pc2
        out_normal[c, 0] = up[0]
        out_normal[c, 1] = up[1]
        out_normal[c, 2] = up[2]
        if folded:
            out_state[c] = 2
            continue
        if n_inside >= 4:
            sp = np.sqrt(np.pi * reach * reach / n_inside)
        r_fit = max(radius, 2.0 * sp)
        p0, gx, gy, qa, qb, qc = _fit_quadric_points(xl, yl, hgt, dist, keep, r_fit)
        quad[0], quad[1], quad[2], quad[3], quad[4], quad[5] = p0, gx, gy, qa, qb, qc
        grid, known, nh = _residual_grid(xl, yl, hgt, keep, sp, limit, p0, gx, gy, qa, qb, qc)
        local = _fill_holes(grid, known)
        # slope: the fitted base's normal against the crater's vertical (-gravity)
        slope = _slope_deg(up[0], up[1], up[2], e0, e1, e2, n0, n1, n2, gx, gy,
                           vertical[c, 0], vertical[c, 1], vertical[c, 2])
        out_slope[c] = slope
        out_spacing[c] = sp
        if slope_erosion and slope >= full_deg:
            out_state[c] = 1
            continue
        scale = slope_factor(slope, onset_deg, full_deg) if slope_erosion else 1.0
        rim_offsets(local, float(nh), float(nh), sp, radius, rim_tabs[c], 0.0, 0.0, 0.0, delta)
        octaves = roughness_octaves(radius, sp)
        rc = crater_rough(rough, warps[c])
        dh = np.empty(keep)
        if keep >= PARALLEL_MIN:
            _write_parallel(pos, heights, idx[:keep], dist[:keep], az[:keep], xl[:keep],
                            yl[:keep], hgt[:keep], up, radius, tabs[c], scale, depths[c], xe,
                            rim_tabs[c], delta, quad, rc, seeds[c], radius, octaves, gain, dh)
        else:
            _write_range(_FIRST, keep, pos, heights, idx, dist, az, xl, yl, hgt, up, radius,
                         tabs[c], scale, depths[c], xe, rim_tabs[c], delta, quad, rc, seeds[c],
                         radius, octaves, gain, dh)
        _record(c, scale, dh, keep, out_scale, out_maxdh, out_nvert)


@njit(cache=True, parallel=True)
def _point_mass_kernel(points, centres, masses, soft, out):
    """Softened point-mass attraction sum_j m_j d_j / (|d_j|^2 + soft)^1.5 (d_j = centre j
    - point; G = density = 1) at every point; each point's row is its own (any thread
    count gives the same sums, added in the same order)."""
    for p in prange(points.shape[0]):
        g0 = 0.0
        g1 = 0.0
        g2 = 0.0
        for j in range(centres.shape[0]):
            d0 = centres[j, 0] - points[p, 0]
            d1 = centres[j, 1] - points[p, 1]
            d2 = centres[j, 2] - points[p, 2]
            r2 = d0 * d0 + d1 * d1 + d2 * d2 + soft
            w = masses[j] / (r2 * np.sqrt(r2))
            g0 += w * d0
            g1 += w * d1
            g2 += w * d2
        out[p, 0] = g0
        out[p, 1] = g1
        out[p, 2] = g2
