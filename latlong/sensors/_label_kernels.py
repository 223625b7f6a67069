"""Numba kernels of the crater labels (latlong.sensors.labels): a uniform grid over the
surface points, then each crater tests the points of the cells its bounding ball (2 R)
touches. The youngest crater containing a point (the last row) wins."""

from __future__ import annotations

import numpy as np
from numba import njit, prange


@njit(cache=True)
def _finite_box_kernel(points, finite, lo, hi):
    """Mark the finite rows of ``points`` in ``finite`` and write their box into ``lo``,
    ``hi`` (left untouched without finite rows); returns how many are finite."""
    n = 0
    for i in range(points.shape[0]):
        x, y, z = points[i, 0], points[i, 1], points[i, 2]
        ok = np.isfinite(x) and np.isfinite(y) and np.isfinite(z)
        finite[i] = ok
        if ok:
            if n == 0:
                lo[0], lo[1], lo[2] = x, y, z
                hi[0], hi[1], hi[2] = x, y, z
            else:
                lo[0], lo[1], lo[2] = min(lo[0], x), min(lo[1], y), min(lo[2], z)
                hi[0], hi[1], hi[2] = max(hi[0], x), max(hi[1], y), max(hi[2], z)
            n += 1
    return n


@njit(cache=True)
def _bin_points_kernel(points, lo, h, dims, offsets, order):
    """Counting sort of ``points`` into the cells of a grid (origin ``lo``, cell ``h``,
    ``dims`` cells per axis): ``order[offsets[c]:offsets[c + 1]]`` are the points of
    cell ``c`` (``offsets`` has prod(dims) + 1 entries, zeroed by the caller)."""
    n = points.shape[0]
    cell = np.empty(n, np.int64)
    for i in range(n):
        ix = min(max(int((points[i, 0] - lo[0]) / h), 0), dims[0] - 1)
        iy = min(max(int((points[i, 1] - lo[1]) / h), 0), dims[1] - 1)
        iz = min(max(int((points[i, 2] - lo[2]) / h), 0), dims[2] - 1)
        c = (ix * dims[1] + iy) * dims[2] + iz
        cell[i] = c
        offsets[c + 1] += 1
    for c in range(offsets.shape[0] - 1):
        offsets[c + 1] += offsets[c]
    fill = offsets[:-1].copy()
    for i in range(n):
        order[fill[cell[i]]] = i
        fill[cell[i]] += 1


@njit(cache=True, parallel=True)
def _label_kernel(points, lo, h, dims, offsets, order, centres, radii, normals, use_normals,
                  n_thr, out):
    """Write into ``out`` the last crater (row) containing each point (module notes of
    latlong.sensors.labels for the two rules); untouched points keep their value. The last
    row is the largest, whatever order the rows are tested in: each thread tests every
    ``n_thr``-th row (numba's thread count, given: rows in random places, balanced work)
    and keeps the largest it finds per point (int32), and the threads' largest are
    merged: the sequential answer, the same bytes on any thread count."""
    n = points.shape[0]
    best = np.full((n_thr, n), -1, dtype=np.int32)
    for t in prange(n_thr):
        for row in range(t, centres.shape[0], n_thr):  # rows grow: the last write wins
            _label_row(points, lo, h, dims, offsets, order, centres, radii, normals,
                       use_normals, row, best[t])
    for p in prange(n):
        m = -1
        for t in range(n_thr):
            m = max(m, np.int64(best[t, p]))
        if m >= 0:
            out[p] = m


@njit(cache=True, inline="always")
def _label_row(points, lo, h, dims, offsets, order, centres, radii, normals, use_normals,
               row, out):
    """Write ``row`` into ``out`` at the points crater ``row`` contains."""
    cx, cy, cz = centres[row, 0], centres[row, 1], centres[row, 2]
    r = radii[row]
    reach = 2.0 * r
    i0 = max(int((cx - reach - lo[0]) / h), 0)
    i1 = min(int((cx + reach - lo[0]) / h), dims[0] - 1)
    j0 = max(int((cy - reach - lo[1]) / h), 0)
    j1 = min(int((cy + reach - lo[1]) / h), dims[1] - 1)
    k0 = max(int((cz - reach - lo[2]) / h), 0)
    k1 = min(int((cz + reach - lo[2]) / h), dims[2] - 1)
    rc = np.sqrt(cx * cx + cy * cy + cz * cz)
    nx, ny, nz = normals[row, 0], normals[row, 1], normals[row, 2]
    for i in range(i0, i1 + 1):
        for j in range(j0, j1 + 1):
            for k in range(k0, k1 + 1):
                c = (i * dims[1] + j) * dims[2] + k
                for s in range(offsets[c], offsets[c + 1]):
                    p = order[s]
                    px, py, pz = points[p, 0], points[p, 1], points[p, 2]
                    if use_normals:
                        dx, dy, dz = px - cx, py - cy, pz - cz
                        hh = dx * nx + dy * ny + dz * nz
                        ex, ey, ez = dx - hh * nx, dy - hh * ny, dz - hh * nz
                        if abs(hh) <= r and ex * ex + ey * ey + ez * ez <= r * r:
                            out[p] = row
                    else:
                        rq = np.sqrt(px * px + py * py + pz * pz)
                        qx = py * cz - pz * cy
                        qy = pz * cx - px * cz
                        qz = px * cy - py * cx
                        cross = np.sqrt(qx * qx + qy * qy + qz * qz)
                        arc = rc * np.arctan2(cross, px * cx + py * cy + pz * cz)
                        if arc <= r and abs(rq - rc) <= r:
                            out[p] = row
