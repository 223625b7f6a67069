"""Numba kernels of cube-sphere cell sets for terrain on demand
(:mod:`latlong.ondemand.cellsets`): each output row from its own input row, so the
results do not depend on the thread count. The face arithmetic is
:mod:`craters.kernels`'s (one home with :mod:`craters.cells`)."""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from craters.kernels import cell_id, face_point, face_uv, read_only_inputs


@read_only_inputs("out")
@njit(cache=True, parallel=True)
def _cells_kernel(points, level, out):
    """Cell id of each direction at ``level``."""
    for k in prange(points.shape[0]):
        f, u, v = face_uv(points[k, 0], points[k, 1], points[k, 2])
        out[k] = cell_id(level, f, u, v)


@njit(cache=True, parallel=True)
def _neighbourhood_kernel(ids, out):
    """The 9 cells around each cell (itself and the 8 next to it, across face edges; at a
    cube corner one of them repeats): ``out`` (n, 9) uint64."""
    mask = np.uint64((1 << 27) - 1)
    for k in prange(ids.shape[0]):
        c = ids[k]
        level = int(c >> np.uint64(57))
        face = int((c >> np.uint64(54)) & np.uint64(7))
        i = int((c >> np.uint64(27)) & mask)
        j = int(c & mask)
        scale = 2.0 / (1 << level)
        t = 0
        for di in (-1, 0, 1):
            for dj in (-1, 0, 1):
                u = -1.0 + (i + 0.5 + di) * scale
                v = -1.0 + (j + 0.5 + dj) * scale
                w0, w1, w2 = face_point(face, u, v)
                f2, u2, v2 = face_uv(w0, w1, w2)
                out[k, t] = cell_id(level, f2, u2, v2)
                t += 1


@njit(cache=True, parallel=True)
def _window_kernel(c, e, n, coords, out):
    """Unit directions of the pixel centres of a gnomonic window: ``c + x e + y n``
    normalised, x = coords[col], y = -coords[row] (numpy's order of operations, for the
    same bits: :func:`latlong.ondemand.tile.tile_units`)."""
    size = coords.shape[0]
    for r in prange(size):
        y = -coords[r]
        for q in range(size):
            x = coords[q]
            v0 = c[0] + x * e[0] + y * n[0]
            v1 = c[1] + x * e[1] + y * n[1]
            v2 = c[2] + x * e[2] + y * n[2]
            norm = np.sqrt(v0 * v0 + v1 * v1 + v2 * v2)
            out[r, q, 0] = v0 / norm
            out[r, q, 1] = v1 / norm
            out[r, q, 2] = v2 / norm


@njit(cache=True, parallel=True)
def _reach_kernel(centres, angles, level, occ, out):
    """Whether a cap (unit centre, angular radius) may touch an occupied cell (sorted ids
    ``occ`` at ``level``): a superset test. The cap's box on its centre's cube face is
    padded by its angle times the face's largest stretch over the box (sec^2 = 1 + u^2 +
    v^2 of the gnomonic face, at most 3 at its corners) and every cell of the box is
    looked up, row by row (a row of the box is one run of the sorted ids); a box leaving
    the face or taller than 4096 rows counts as touching."""
    nside = 1 << level
    for k in prange(centres.shape[0]):
        f, u, v = face_uv(centres[k, 0], centres[k, 1], centres[k, 2])
        # the stretch is sec^2 = 1 + u^2 + v^2 at most over the box padded by 3 x angle
        wide = 3.0 * angles[k]
        stretch = 1.0 + (abs(u) + wide) ** 2 + (abs(v) + wide) ** 2
        pad = min(stretch, 3.0) * angles[k] * (1.0 + 1e-9) + 1e-12
        if u - pad <= -1.0 or u + pad >= 1.0 or v - pad <= -1.0 or v + pad >= 1.0:
            out[k] = True
            continue
        i0 = int(np.floor((u - pad + 1.0) * 0.5 * nside))
        i1 = int(np.floor((u + pad + 1.0) * 0.5 * nside))
        j0 = int(np.floor((v - pad + 1.0) * 0.5 * nside))
        j1 = int(np.floor((v + pad + 1.0) * 0.5 * nside))
        if i1 - i0 > 4096:
            out[k] = True
            continue
        # each row i of the box is one run of ``occ`` (ids sort by face, i, then j)
        hit = False
        for i in range(i0, i1 + 1):
            row = (np.uint64(level) << np.uint64(57)) | (np.uint64(f) << np.uint64(54)) \
                | (np.uint64(i) << np.uint64(27))
            lo = np.searchsorted(occ, row | np.uint64(j0))
            if lo < occ.shape[0] and occ[lo] <= (row | np.uint64(j1)):
                hit = True
                break
        out[k] = hit
