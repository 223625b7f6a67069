"""Numba kernels: casting every grid direction from a centre onto a triangle mesh."""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ._crater_kernels import _gather_kernel
from ._grid_kernels import _ray_triangle

_BARY_TOL = 1e-10  # accept hits this far outside a triangle: edges are hit twice, never missed


@njit(cache=True, inline="always")
def _ray_hit(dx, dy, dz, a, b, c):
    """t of the ray from the origin along d through triangle (a, b, c), or -1 (hits up
    to ``_BARY_TOL`` outside the triangle count)."""
    u, v, t = _ray_triangle(dx, dy, dz, a, b, c)
    if u < -_BARY_TOL or u > 1.0 + _BARY_TOL or v < -_BARY_TOL or u + v > 1.0 + _BARY_TOL:
        return -1.0
    return t if t > 0.0 else -1.0


@njit(cache=True)
def _raycast_kernel(m, ring_offsets, unit, verts, faces, margin, count, tmin, tmax):
    """For every grid direction: number of distinct crossings, nearest and farthest t.

    Triangle by triangle: the cap around the triangle's directions (plus ``margin``
    radians) is gathered through the ring structure, and only those directions are
    tested, so the cost is O(F * directions per triangle + N). Hits within a relative
    1e-9 of an already recorded nearest/farthest crossing are the same crossing seen
    through two triangles (a shared edge or vertex) and are not counted again.
    """
    for f in range(faces.shape[0]):
        a = verts[faces[f, 0]]
        b = verts[faces[f, 1]]
        c = verts[faces[f, 2]]
        na = np.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])
        nb = np.sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2])
        nc = np.sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2])
        sx = a[0] / na + b[0] / nb + c[0] / nc
        sy = a[1] / na + b[1] / nb + c[1] / nc
        sz = a[2] / na + b[2] / nb + c[2] / nc
        sn = np.sqrt(sx * sx + sy * sy + sz * sz)
        if sn < 1e-9:
            ang = np.pi
            colat = 0.0
            lon = 0.0
        else:
            sx /= sn
            sy /= sn
            sz /= sn
            ang = 0.0
            for p, n in ((a, na), (b, nb), (c, nc)):
                d = (p[0] * sx + p[1] * sy + p[2] * sz) / n
                ang = max(ang, np.arccos(min(1.0, max(-1.0, d))))
            ang = min(np.pi, ang + margin)
            colat = np.arccos(min(1.0, max(-1.0, sz)))
            lon = np.arctan2(sy, sx)
        n_cand = _gather_kernel(m, ring_offsets, colat, lon, ang, np.empty(0, np.int64),
                                np.bool_(True))
        cand = np.empty(n_cand, np.int64)
        _gather_kernel(m, ring_offsets, colat, lon, ang, cand, np.bool_(False))
        for q in range(n_cand):
            i = cand[q]
            t = _ray_hit(unit[i, 0], unit[i, 1], unit[i, 2], a, b, c)
            if t <= 0.0:
                continue
            if count[i] == 0:
                count[i] = 1
                tmin[i] = t
                tmax[i] = t
                continue
            tol = 1e-9 * max(t, tmax[i])
            if abs(t - tmin[i]) <= tol or abs(t - tmax[i]) <= tol:
                continue
            count[i] += 1
            if t < tmin[i]:
                tmin[i] = t
            if t > tmax[i]:
                tmax[i] = t


@njit(cache=True, parallel=True)
def _brute_force_kernel(unit, verts, faces, count, tmin, tmax):
    """Reference: every direction against every triangle (for tests and benchmarks)."""
    for i in prange(unit.shape[0]):
        n = 0
        lo = np.inf
        hi = 0.0
        for f in range(faces.shape[0]):
            t = _ray_hit(unit[i, 0], unit[i, 1], unit[i, 2], verts[faces[f, 0]],
                              verts[faces[f, 1]], verts[faces[f, 2]])
            if t <= 0.0:
                continue
            if n == 0:
                n = 1
                lo = t
                hi = t
                continue
            tol = 1e-9 * max(t, hi)
            if abs(t - lo) <= tol or abs(t - hi) <= tol:
                continue
            n += 1
            lo = min(lo, t)
            hi = max(hi, t)
        count[i] = n
        tmin[i] = lo if n else 0.0
        tmax[i] = hi
